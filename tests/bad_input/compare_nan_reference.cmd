compare half.exr some_nan.exr
