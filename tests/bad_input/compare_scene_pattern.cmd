compare '{scene}.{frame}.exr' 'half{frame}.exr' --frames 0:2 --csv seq.csv
