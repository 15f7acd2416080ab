compare half.png half.exr
