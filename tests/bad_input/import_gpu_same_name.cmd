import-gpu gpu_a/frame.gpuframe gpu_b/frame.gpuframe -o gpu_out
