import-gpu gpu_huge.gpuframe
