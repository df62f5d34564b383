"""OCC's optimal bounding boxes, cached by shape identity.

`optimalBoundingBox(False)` is read from the geometry, not from a triangulation (`BoundBox`
is taken from one when the shape has it, and can then fall short of a curved face); it
only errs on the large side. It costs ~0.3 ms per B-spline face, and the face-by-face
sections, the centroidal axis and the decomposition ask again and again for faces that a
Boolean left untouched (same TShape).
"""
from __future__ import annotations

import numpy as np

#: Boxes by shape hash. Entries keep their shape alive, so its address cannot be recycled
#: for another shape while cached; a hit is confirmed with `isSame` (same TShape and
#: location, which fix the box).
_BOXES: dict[int, list[tuple[object, object]]] = {}
_CACHED = [0]
MAX_CACHED_BOXES = 20000


def optimal_box(shape):
    """The shape's optimal bounding box (do not modify it: it is shared)."""
    bucket = _BOXES.setdefault(shape.hashCode(), [])
    for known, box in bucket:
        if known.isSame(shape):
            return box
    if _CACHED[0] >= MAX_CACHED_BOXES:
        _BOXES.clear()
        _CACHED[0] = 0
        bucket = _BOXES.setdefault(shape.hashCode(), [])
    box = shape.optimalBoundingBox(False)
    bucket.append((shape, box))
    _CACHED[0] += 1
    return box


def box_reach(box, n: np.ndarray) -> float:
    """The highest value of x·n over the box."""
    return float(sum(max(lo * c, hi * c) for lo, hi, c in
                     ((box.XMin, box.XMax, n[0]), (box.YMin, box.YMax, n[1]),
                      (box.ZMin, box.ZMax, n[2]))))
