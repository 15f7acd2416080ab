converge ok.toml --reference half.exr --sequence 2
