cost ok.toml -D gpu.coefficients=\"coef_unknown.json\"
