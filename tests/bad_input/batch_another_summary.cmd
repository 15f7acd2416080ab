batch --scene ok.toml --output-dir batch_other
