compare half.exr half.png
