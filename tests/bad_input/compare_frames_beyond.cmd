compare 'half{frame}.exr' 'half{frame}.exr' --frames 0:4294967296 --csv seq.csv
