// colour_model kernels (placeholder)
