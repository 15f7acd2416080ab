converge ok.toml --reference ref_ok.exr --frame 2 --estimators uniform -o conv_out/c
