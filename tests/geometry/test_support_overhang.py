"""Overhang area against closed forms: planar faces exactly, curved faces to 0.5 %."""
from __future__ import annotations

import math

import pytest

from freecad_conformal.geometry.overhang import overhang_area, overhang_report

ANGLE = math.radians(45.0)


@pytest.mark.parametrize("radius", [5.0, 12.5])
def test_sphere_cap_below_the_45_degree_line(Part, radius):
    sphere = Part.makeSphere(radius)
    expected = 2 * math.pi * radius ** 2 * (1 - math.cos(ANGLE))
    area = overhang_area(sphere, (0, 0, 1), ANGLE, on_bed=False)
    assert area == pytest.approx(expected, rel=5e-3)


def test_sphere_overhang_is_the_same_in_every_direction(Part):
    sphere = Part.makeSphere(8.0)
    up = overhang_area(sphere, (0, 0, 1), ANGLE, on_bed=False)
    tilted = overhang_area(sphere, (1, 1, 1), ANGLE, on_bed=False)
    assert tilted == pytest.approx(up, rel=5e-3)


def test_inverted_cone_overhangs_only_beyond_its_wall_angle(Part):
    # Wall 45° from the axis, opening upwards: overhangs at a 30° limit, not at 60°.
    cone = Part.makeCone(0.0, 10.0, 10.0)
    wall = cone.Faces[0].Area
    assert overhang_area(cone, (0, 0, 1), math.radians(30), on_bed=False) == pytest.approx(wall, rel=1e-9)
    assert overhang_area(cone, (0, 0, 1), math.radians(60), on_bed=False) == pytest.approx(0.0, abs=1e-6)


def test_box_on_the_bed_has_no_overhang_and_its_ceiling_when_lifted(Part):
    box = Part.makeBox(10, 20, 5)
    assert overhang_area(box, (0, 0, 1), ANGLE) == 0.0
    report = overhang_report(box, (0, 0, 1), ANGLE, on_bed=False)
    assert report.area == pytest.approx(200.0)
    assert len(report.faces) == 1


def test_cylinder_built_sideways_overhangs_on_its_lower_quarter(Part):
    # Axis along X, built along +Z: the lateral strip with n·z < −sin 45° spans 90° of 360°.
    cylinder = Part.makeCylinder(5.0, 20.0, Part.Vertex(0, 0, 0).Point, Part.Vertex(1, 0, 0).Point)
    lateral = 2 * math.pi * 5.0 * 20.0
    area = overhang_area(cylinder, (0, 0, 1), ANGLE, on_bed=False)
    assert area == pytest.approx(lateral / 4, rel=5e-3)
