converge ok.toml --reference half.exr --min-effort 8 --max-effort 2
