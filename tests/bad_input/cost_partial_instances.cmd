cost ok.toml -D geometry.layout="instances" -D geometry.build="partial" -q -o cost_out/c.json
