converge ok.toml --reference half.exr --frame 4294967295
