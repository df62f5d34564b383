"""OCC's optimal bounding boxes, cached by shape identity.

`optimalBoundingBox(False)` is read from the geometry, not from a triangulation (`BoundBox`
is taken from one when the shape has it, and can then fall short of a curved face); it
only errs on the large side. It costs ~0.3 ms per B-spline face, and the face-by-face
sections, the centroidal axis and the decomposition ask again and again for faces that a
Boolean left untouched (cached by identity: `shape_cache.py`).
"""
from __future__ import annotations

import numpy as np

from freecad_conformal.geometry.shape_cache import ShapeCache

_BOXES = ShapeCache(limit=20000, oriented=False)


def optimal_box(shape):
    """The shape's optimal bounding box (do not modify it: it is shared)."""
    return _BOXES.get((shape,), lambda: shape.optimalBoundingBox(False))


def box_reach(box, n: np.ndarray) -> float:
    """The highest value of x·n over the box."""
    return float(sum(max(lo * c, hi * c) for lo, hi, c in
                     ((box.XMin, box.XMax, n[0]), (box.YMin, box.YMax, n[1]),
                      (box.ZMin, box.ZMax, n[2]))))
