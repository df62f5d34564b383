"""Deposition paths: 2D fills per layer (shapely), 2D -> 3D poses, toolpath assembly, preview."""
