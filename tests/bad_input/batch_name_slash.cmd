batch jobs_slash.toml --quiet --output-dir batch_out
