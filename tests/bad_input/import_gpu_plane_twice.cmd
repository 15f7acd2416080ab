import-gpu gpu_plane_twice.gpuframe -o import_out
