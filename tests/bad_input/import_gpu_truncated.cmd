import-gpu truncated.gpuframe -o import_out
