cost ok.toml -D geometry.layout="aabbs" -D geometry.alpha="disc" -D gpu.omm="4state" -q -o cost_out/c.json
