"""Cached optimal boxes and the shape-identity cache behind them."""
from __future__ import annotations

import pytest

from freecad_conformal.geometry import samples
from freecad_conformal.geometry.boxes import box_reach, optimal_box


def _bounds(box) -> tuple:
    return (box.XMin, box.YMin, box.ZMin, box.XMax, box.YMax, box.ZMax)


def test_a_moved_face_gets_its_own_box_not_the_cached_one(App):
    solid = samples.hinge()
    face = solid.Faces[0]
    first = _bounds(optimal_box(face))
    assert first == pytest.approx(_bounds(face.optimalBoundingBox(False)))
    # Same TShape, another location: the box must follow the location.
    moved_face = face.translated(App.Vector(100, 0, 0))
    assert moved_face.isPartner(face)
    again = _bounds(optimal_box(moved_face))
    assert again[0] == pytest.approx(first[0] + 100) and again[3] == pytest.approx(first[3] + 100)
    assert _bounds(optimal_box(face)) == first


def test_box_reach_is_the_highest_corner_along_a_direction(Part):
    import numpy as np

    box = Part.makeBox(10, 20, 30).BoundBox
    assert box_reach(box, np.array([0, 0, 1.0])) == pytest.approx(30)
    assert box_reach(box, np.array([0, -1.0, 0])) == pytest.approx(0)
    n = np.array([1.0, 1.0, 0]) / np.sqrt(2)
    assert box_reach(box, n) == pytest.approx(30 / np.sqrt(2))


def test_shape_cache_tells_orientation_apart_when_asked():
    from freecad_conformal.geometry.shape_cache import ShapeCache

    face = samples.l_block().Faces[0]
    reversed_face = face.reversed()
    oriented, plain = ShapeCache(limit=10, oriented=True), ShapeCache(limit=10, oriented=False)
    assert oriented.get((face,), lambda: 1) == 1
    assert oriented.get((reversed_face,), lambda: 2) == 2
    assert oriented.get((face,), lambda: 3) == 1
    assert plain.get((face,), lambda: 1) == 1
    assert plain.get((reversed_face,), lambda: 2) == 1


def test_shape_cache_starts_over_at_its_limit():
    from freecad_conformal.geometry.shape_cache import ShapeCache

    faces = samples.hinge().Faces[:3]
    cache = ShapeCache(limit=2, oriented=False)
    for i, face in enumerate(faces):
        assert cache.get((face,), lambda i=i: i) == i
    # The third entry cleared the first two: they are computed again.
    assert cache.get((faces[0],), lambda: "again") == "again"
    assert cache.get((faces[2],), lambda: "stale") == 2


def test_a_copy_turned_by_a_right_angle_takes_its_boxes_moved(App):
    """A sub-part turned onto the platform (here the hinge, turned 90° about −Y and moved)
    gets its faces' and edges' boxes from the original's: each holds the moved shape and
    is OCC's own box of it within OCC's gap, in whichever direction the turn goes."""
    import numpy as np

    from freecad_conformal.geometry.boxes import _BOXES
    from freecad_conformal.geometry.solids import moved_rigidly

    solid = samples.hinge()
    for face in solid.Faces:
        optimal_box(face)
    for edge in solid.Edges:
        optimal_box(edge)
    moved = solid.copy()
    moved.rotate(App.Vector(1, 2, 3), App.Vector(0, -1, 0), 90)
    moved.translate(App.Vector(-40, 7, 0))
    moved_rigidly(solid, moved)
    for shape in moved.Faces + moved.Edges:
        seeded = _BOXES.peek((shape,))
        assert seeded is not None
        assert _bounds(seeded) == pytest.approx(_bounds(shape.optimalBoundingBox(False)), abs=1e-6)
        points = np.array([tuple(v.Point) for v in shape.Vertexes])
        low, high = np.array(_bounds(seeded)[:3]), np.array(_bounds(seeded)[3:])
        assert np.all(points >= low - 1e-9) and np.all(points <= high + 1e-9)


def test_a_copy_turned_by_another_angle_is_boxed_by_occ(App):
    from freecad_conformal.geometry.boxes import _BOXES
    from freecad_conformal.geometry.solids import moved_rigidly

    solid = samples.hinge()
    for face in solid.Faces:
        optimal_box(face)
    moved = solid.copy()
    moved.rotate(App.Vector(0, 0, 0), App.Vector(0, -1, 0), 30)
    moved_rigidly(solid, moved)
    assert all(_BOXES.peek((face,)) is None for face in moved.Faces)
    assert _bounds(optimal_box(moved.Faces[0])) == _bounds(moved.Faces[0].optimalBoundingBox(False))
