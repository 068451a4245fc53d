// transfer_function_edit kernels (placeholder)
