"""Layers of one sub-part: the layer model, planar (uniform, adaptive) and 3-D layers."""
