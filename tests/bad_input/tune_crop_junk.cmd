tune ok.toml --budget-ms 5 --error-crops 1x1 --crop-size 16x9junk -o tune_out/t
