compare 'seqimg.{frame}.exr' 'seqimg.{frame}.exr' --frames 0:2 --csv seq.png
