batch jobs_escape.toml --quiet --output-dir batch_out
