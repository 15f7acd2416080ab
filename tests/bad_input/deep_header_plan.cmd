plan deep_header.toml
