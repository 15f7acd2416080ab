render ok.toml --quiet -o adir.exr
