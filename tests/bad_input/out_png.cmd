render ok.toml --quiet -o x.png
