// enhancement kernels (placeholder)
