converge ok.toml --reference ref_ok.exr --reference ref_ok.exr -o conv_out/c
