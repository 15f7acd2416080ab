compare 'seqimg.{frame}.exr' 'seqimg.{frame}.exr' --frames 0:4000000000 --csv seq.csv
