bias ok.toml --reference ref_plain.exr --strict --estimators exact --seeds 2 -o bias_out/b
