bias ok.toml --reference half.exr --seeds 1
