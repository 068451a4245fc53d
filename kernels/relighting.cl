// relighting kernels (placeholder)
