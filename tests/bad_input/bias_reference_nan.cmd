bias ok.toml --reference ref_nan.exr --estimators exact --seeds 2 -o bias_out/b
