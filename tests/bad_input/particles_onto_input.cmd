particles selfseq.toml --out .
