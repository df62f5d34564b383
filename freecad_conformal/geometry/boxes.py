"""OCC's optimal bounding boxes, cached by shape identity.

`optimalBoundingBox(False)` is read from the geometry, not from a triangulation (`BoundBox`
is taken from one when the shape has it, and can then fall short of a curved face); it
only errs on the large side. It costs ~0.3 ms per B-spline face, and the face-by-face
sections, the centroidal axis and the decomposition ask again and again for faces that a
Boolean left untouched (cached by identity: `shape_cache.py`).
"""
from __future__ import annotations

import numpy as np

from freecad_conformal.geometry.shape_access import placement_move
from freecad_conformal.geometry.shape_cache import ShapeCache

_BOXES = ShapeCache(limit=20000, oriented=False)


def optimal_box(shape):
    """The shape's optimal bounding box (do not modify it: it is shared)."""
    return _BOXES.get((shape,), lambda: shape.optimalBoundingBox(False))


def box_values(box) -> tuple[float, ...]:
    """A box as (XMin, YMin, ZMin, XMax, YMax, ZMax): what another process rebuilds it from."""
    return (box.XMin, box.YMin, box.ZMin, box.XMax, box.YMax, box.ZMax)


def seed_boxes(shapes, values) -> None:
    """Record each of `shapes`' optimal box as given by `box_values` (boxed in another
    process: a worker's copy of its parent's solid, read from OCC's binary format)."""
    from freecad_conformal.freecad_env import import_freecad

    App, _ = import_freecad()
    for shape, value in zip(shapes, values):
        _BOXES.get((shape,), lambda value=value: App.BoundBox(*value))


#: A turn whose matrix lies this close to one of signed unit axes permutes boxes exactly
#: (up to rounding); any other turn would make a moved box loose.
RIGHT_ANGLE_SLACK = 1e-12


def seed_moved_boxes(original, moved) -> None:
    """Record the boxes of `moved`'s faces and edges, `moved` being `original` given a new
    location (copied, turned, translated): each is the original's cached box moved. Only for
    turns by right angles about the axes (roots built along ±X, ±Y, ±Z), where that is OCC's
    box of the moved shape but for rounding: boxing the sub-part the bottle's layers cut,
    turned onto the platform, took 0.16 s of them."""
    move = placement_move(original, moved)
    turn = np.array([[move.A11, move.A12, move.A13], [move.A21, move.A22, move.A23],
                     [move.A31, move.A32, move.A33]])
    if np.max(np.abs(turn - np.round(turn))) > RIGHT_ANGLE_SLACK:
        return
    for kind in ("Faces", "Edges"):
        for shape, twin in zip(getattr(original, kind), getattr(moved, kind)):
            box = _BOXES.peek((shape,))
            if box is not None:
                _BOXES.get((twin,), lambda box=box: box.transformed(move))


def box_reach(box, n: np.ndarray) -> float:
    """The highest value of x·n over the box."""
    return float(sum(max(lo * c, hi * c) for lo, hi, c in
                     ((box.XMin, box.XMax, n[0]), (box.YMin, box.YMax, n[1]),
                      (box.ZMin, box.ZMax, n[2]))))
