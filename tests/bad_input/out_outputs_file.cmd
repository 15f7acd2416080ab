render ok.toml --quiet -o new/x.exr --outputs-file ok.toml
