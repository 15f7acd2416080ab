converge ok.toml --reference ref_nan.exr --estimators uniform -o conv_out/c
