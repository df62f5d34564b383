"""Cached optimal boxes: a cached box belongs to the same face in the same place."""
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
