batch jobs_ok.toml --quiet --summary jobs_ok.toml
