import-gpu not_gpuframe.gpuframe -o import_out
