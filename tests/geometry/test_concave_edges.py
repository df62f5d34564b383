"""Inner angles of edges, measured inside the material from OCC normals."""
from __future__ import annotations

import math

import pytest

from freecad_conformal.geometry import samples
from freecad_conformal.geometry.concave_edges import concave_edges, edge_angles


def test_box_edges_are_all_90_degrees_inside(Part):
    angles = edge_angles(Part.makeBox(10, 20, 30))
    assert len(angles) == 12
    assert all(math.degrees(a.inner_angle) == pytest.approx(90.0) for a in angles)
    assert concave_edges(Part.makeBox(10, 20, 30)) == []


def test_l_block_inner_edge_is_270_degrees_inside():
    block = samples.l_block()
    concave = concave_edges(block)
    assert len(concave) == 1
    assert math.degrees(concave[0].inner_angle) == pytest.approx(270.0)
    convex = [a for a in edge_angles(block) if not a.concave]
    assert convex and all(math.degrees(a.inner_angle) == pytest.approx(90.0) for a in convex)


def test_wedge_edge_angle_is_the_wedge_angle(Part, App):
    # A prism whose cross-section is a right triangle with a 30° corner.
    import math as m
    h = 10.0 * m.tan(m.radians(30))
    wire = Part.makePolygon([App.Vector(0, 0, 0), App.Vector(10, 0, 0), App.Vector(10, h, 0),
                             App.Vector(0, 0, 0)])
    prism = Part.Face(wire).extrude(App.Vector(0, 0, 5))
    inner = sorted(round(math.degrees(a.inner_angle), 6) for a in edge_angles(prism))
    assert inner.count(30.0) == 1 and inner.count(60.0) == 1
    assert inner.count(90.0) == 7


def test_cylinder_on_a_plate_meets_it_concavely_all_round(Part, App):
    plate = Part.makeBox(40, 40, 5)
    peg = Part.makeCylinder(5, 20, App.Vector(20, 20, 5))
    concave = concave_edges(plate.fuse(peg).removeSplitter())
    assert concave
    assert all(math.degrees(e.inner_angle) == pytest.approx(270.0, abs=0.5) for e in concave)
