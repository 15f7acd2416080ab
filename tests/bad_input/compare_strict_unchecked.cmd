compare half.exr half.exr --strict
