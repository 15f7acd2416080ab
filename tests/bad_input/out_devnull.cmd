render ok.toml --quiet -o devnull.exr
