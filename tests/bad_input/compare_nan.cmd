compare some_nan.exr half.exr
