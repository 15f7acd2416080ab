tune ok.toml --budget-ms 5 --error-crops 1x1 --crop-size 4294967312x9 -o tune_out/t
