bias ok.toml --reference ref_ok.exr --estimators restir --seeds 2 -o bias_out/b
