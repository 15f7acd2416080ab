compare all_nan.exr half.exr --allow-nonfinite
