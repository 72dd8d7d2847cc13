/* Software pictures (no GL): a small z-buffered rasterizer for refined meshes. */
