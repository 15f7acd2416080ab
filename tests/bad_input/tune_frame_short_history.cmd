tune ok.toml --budget-ms 5 --error-crops 1x1 --crop-size 32x16 --frame 30 -o tune_out/t
