bias ok.toml --reference ref_ok.exr --reference ref_ok.exr --estimators exact --seeds 2 -o bias_out/b
