batch jobs_dotdot.toml --quiet --output-dir batch_out
