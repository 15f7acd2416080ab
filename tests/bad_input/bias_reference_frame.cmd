bias ok.toml --reference ref_ok.exr --frame 1 --estimators exact --seeds 2 -o bias_out/b
