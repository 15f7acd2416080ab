render clash.settings.toml --quiet -o clash.exr
