batch deep_jobs.toml --quiet
