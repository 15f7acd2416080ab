tune ok.toml -D camera.file="cams_4_30.csv" --designs restir --budget-ms 5 --error-crops 1x1 --crop-size 32x16 --frame 20 -o tune_out/t
