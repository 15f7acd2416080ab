bias ok.toml --reference ref_ok.exr --estimators restir --history soon --seeds 2 -o bias_out/b
