batch jobs_ok.toml --quiet --summary ok.toml
