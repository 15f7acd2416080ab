batch jobs_empty_name.toml --quiet --output-dir batch_out
