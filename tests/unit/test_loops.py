"""Section loops to polygons: repairs keep the area the loops enclose."""
import numpy as np
import pytest

from freecad_conformal.geometry.loops import Loop, polygons_of_loops, signed_area

#: One of the sliced cylinder's sections (mm): the slice face meets a ruling 0.00015 mm
#: off, so the shell crosses itself at (-13.7752, -99.9994).
KINKED = [[39.381863039846145, 99.99955235505467], [-13.775254073786236, -99.99954987973732],
          [-13.775254073814722, -99.99940335879967], [118.70968688794528, -99.99971240990521],
          [118.7096868924767, -99.99954999898748], [118.7096868924767, 99.9995499989875],
          [118.70968689426081, 99.9997596712454], [39.38186304488045, 99.99948776074596]]


def _loop(points, outer: bool = True, face: int = 0) -> Loop:
    return Loop(outer=outer, points=np.asarray(points, dtype=float), wire=None, face_index=face)


def test_a_kinked_shell_keeps_its_area_as_valid_polygons():
    result = polygons_of_loops([_loop(KINKED)])
    assert result.is_valid
    assert result.area == pytest.approx(abs(signed_area(np.asarray(KINKED))), rel=1e-12)


def test_a_ring_crossing_itself_keeps_both_lobes():
    # A bow tie: its second lobe runs clockwise. Dropping it (a zero buffer does) halves it.
    result = polygons_of_loops([_loop([(0, 0), (2, 2), (2, 0), (0, 2)])])
    assert result.is_valid
    assert result.area == pytest.approx(2.0)


def test_a_hole_labelled_as_shell_still_leaves_the_ring_between():
    # Two of the bottle's sections came with outer and hole swapped (`isSame` missed): a
    # repair trusting the labels empties the island; the area between the rings is the part.
    small = [(1, 1), (3, 1), (3, 3), (1, 3)]
    large = [(0, 0), (0, 4), (4, 4), (4, 0)]
    result = polygons_of_loops([_loop(small), _loop(large, outer=False)])
    assert result.is_valid
    assert result.area == pytest.approx(16.0 - 4.0)
