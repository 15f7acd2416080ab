compare ok.toml half.exr
