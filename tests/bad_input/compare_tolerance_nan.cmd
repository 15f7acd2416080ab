compare half.exr half.exr --tolerance nan
