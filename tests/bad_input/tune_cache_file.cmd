tune ok.toml --budget-ms 5 --error-crops 1x1 --crop-size 32x16 --cache ok.toml -o tune_out/t
