render ok.toml --quiet -o ok.toml
