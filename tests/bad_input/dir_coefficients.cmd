cost ok.toml -D gpu.coefficients=\"adir.exr\"
