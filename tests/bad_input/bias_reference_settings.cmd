bias ok.toml --reference ref_ok.exr -D 'shading.albedo=[0.4,0.4,0.4]' --estimators exact --seeds 2 -o bias_out/b
