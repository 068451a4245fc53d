// view_synthesis kernels (placeholder)
