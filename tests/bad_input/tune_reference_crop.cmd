tune ok.toml --budget-ms 5 --error-crops 2x1 --crop-size 16x16 --reference ref_ok.exr --reference ref_ok.exr -o tune_out/t
