render ok.toml --quiet -o link_to_scene.exr
