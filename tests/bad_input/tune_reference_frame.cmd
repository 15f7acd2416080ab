tune ok.toml --designs restir --budget-ms 5 --error-crops 1x1 --crop-size 32x16 --reference ref_ok.exr -o tune_out/t
