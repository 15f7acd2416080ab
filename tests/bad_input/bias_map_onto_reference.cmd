bias ok.toml --reference ref.power.exr --estimators power --seeds 2 -o ref
