compare huge_window.exr half.exr
