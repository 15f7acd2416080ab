bias ok.toml --z nan
