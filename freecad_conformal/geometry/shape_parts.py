"""A shape's faces and vertex points, read once per shape.

Heights along a direction (a shape's lowest level, its highest vertex, its span) and the
faces of the overhang scans are asked of the same piece again and again by the
decomposition and the layout (the jack's plan choice: 108 lowest levels, 45 overhang
scans). FreeCAD 1.x builds every sub-shape's Python object again at each `shape.Vertexes`
or `shape.Faces` (0.56 and 0.36 ms for the jack's 60 vertices and 36 faces, against 0.05
and 0.02 ms in 0.20). Callers only read what these return.
"""
from __future__ import annotations

import numpy as np

from freecad_conformal.geometry.shape_access import point
from freecad_conformal.geometry.shape_cache import ShapeCache

_POINTS: ShapeCache[list] = ShapeCache(limit=8192, oriented=False)
#: oriented: a reversed shape's faces are reversed too
_FACES: ShapeCache[list] = ShapeCache(limit=8192, oriented=True)


def faces(shape) -> list:
    """`shape.Faces`, read once per shape and orientation (do not modify the list or them)."""
    return _FACES.get((shape,), lambda: list(shape.Faces))


def vertex_points(shape) -> list[np.ndarray]:
    """Each vertex's point, as a float array of 3 (shared: do not modify them)."""
    return _POINTS.get((shape,), lambda: [np.array(point(v)) for v in shape.Vertexes])


def heights(shape, direction: np.ndarray) -> list[float]:
    """Each vertex's height along `direction`, as `np.array(tuple(v.Point)) @ direction`
    gives it (the same products, so the same last bits)."""
    return [float(p @ direction) for p in vertex_points(shape)]
