import-gpu gpu_plane_unknown.gpuframe -o import_out
