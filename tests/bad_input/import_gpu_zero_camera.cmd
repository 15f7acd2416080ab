import-gpu gpu_zero_camera.gpuframe
