tune ok.toml --budget-ms 5 --frame 3 -o tune_out/t
