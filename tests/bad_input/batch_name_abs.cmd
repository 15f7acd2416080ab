batch jobs_abs.toml --quiet --output-dir batch_out
