//! Pictures of a solution: a z-buffered Gouraud rasterizer and tone mapping.
