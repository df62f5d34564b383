"""Pencil passes: where a V-bit stands in a concave corner, and what it leaves there."""
from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from shapely.geometry import Point, Polygon

from freecad_conformal.paths.milling import MillTool
from freecad_conformal.paths.pencil import cutter_outline, flank_pose, outline_at, wedge_poses


def v_bit(tip: float = 0.05, taper: float = 30.0) -> MillTool:
    return MillTool(number=3, id="vbit", diameter=6.0, flute_length=11.2, holder_diameter=20.0,
                    holder_length=50.0, feed=120.0, plunge_feed=40.0, rpm=6000.0, stepover=0.5,
                    taper_deg=taper, tip_diameter=tip, reach=30.0)


def _inward(opening: float) -> list[np.ndarray]:
    return [np.array([0.0, 1.0]), np.array([math.sin(opening), -math.cos(opening)])]


def _cones(opening: float, tool: MillTool) -> list[np.ndarray]:
    flutes, _ = cutter_outline(tool)
    return [outline_at(flutes, *pose) for pose in wedge_poses(opening, tool)]


@pytest.mark.parametrize("degrees", [35.0, 45.0, 90.0, 135.0])
@pytest.mark.parametrize("tip", [0.0, 0.05, 0.4])
def test_flank_lies_on_one_face_and_no_cone_crosses_either(degrees, tip):
    opening, tool = math.radians(degrees), v_bit(tip)
    flutes, _ = cutter_outline(tool)
    origin, axis, across = flank_pose(opening, tool)
    placed = outline_at(flutes, origin, axis, across)
    # the flank: from the tip flat's edge to where the cone meets the shank, on y = 0
    assert placed[0][1] == pytest.approx(0.0, abs=1e-12)
    assert placed[5][1] == pytest.approx(0.0, abs=1e-12)
    for cone in _cones(opening, tool):
        for inward in _inward(opening):
            assert float((cone[[0, 1, 2, 5]] @ inward).min()) >= -1e-9
    # pushed out no further than the tip flat needs: a sharp tip sits in the corner
    if tip == 0.0:
        assert np.linalg.norm(origin) == pytest.approx(0.0, abs=1e-12)


def _left_in_corner(degrees: float, tip: float) -> float:
    """How far (mm) from the nearer face the corner's material reaches after every pass."""
    opening = math.radians(degrees)
    far = 8.0      # past the 6 mm end mill's zone in a 45° wedge (7.24 mm)
    wedge = Polygon([(0, 0), (far, 0), (far * math.cos(opening), far * math.sin(opening))])
    wedge = wedge.intersection(Point(0, 0).buffer(far, quad_segs=64))
    left = wedge.difference(shapely.union_all([Polygon(c) for c in _cones(opening, v_bit(tip))]))
    if left.is_empty:
        return 0.0
    corners = np.array([xy for part in getattr(left, "geoms", [left])
                        for xy in part.exterior.coords])
    return float(max(min(float(p @ n) for n in _inward(opening)) for p in corners))


@pytest.mark.parametrize("degrees", [35.0, 45.0, 60.0, 90.0, 120.0])
def test_passes_leave_only_a_speck_at_the_tip(degrees):
    # a 0.05 mm flat leaves material no further than 0.05 mm from the faces
    assert _left_in_corner(degrees, 0.05) < 0.05
    # and a blunt tip visibly more: the measure sees what the passes leave
    assert _left_in_corner(degrees, 0.4) > 0.05


def test_a_wide_wedge_takes_cones_fanned_between_the_flanks():
    tool = v_bit()
    assert len(wedge_poses(math.radians(45.0), tool)) == 2
    poses = wedge_poses(math.radians(90.0), tool)
    angles = [math.degrees(math.atan2(axis[1], axis[0])) for _, axis, _ in poses]
    assert angles[0] == pytest.approx(15.0) and angles[-1] == pytest.approx(75.0)
    # neighbours at most 0.75 of the 30° cone apart
    assert max(np.diff(angles)) <= 22.5 + 1e-9 and len(poses) == 4
