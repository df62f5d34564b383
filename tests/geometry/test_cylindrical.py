"""Cylindrical sections: exact areas on the cylinder and loops in the unrolled plane."""
from __future__ import annotations

import math

import numpy as np
import pytest

from freecad_conformal.errors import GeometryError
from freecad_conformal.geometry.cylindrical import CylinderAxis, cylindrical_sections


def test_coaxial_cylinder_cuts_a_tube_in_a_full_band(App, Part):
    tube = Part.makeCylinder(10, 20).cut(Part.makeCylinder(5, 20))
    layer = cylindrical_sections(tube, [7.0]).layers[0]
    assert layer.area == pytest.approx(2 * math.pi * 7 * 20, rel=1e-9)
    [loop] = layer.loops
    s, a = loop.points[:, 0], loop.points[:, 1]
    assert s.max() - s.min() == pytest.approx(2 * math.pi * 7, rel=1e-9)   # one full turn
    assert (a.min(), a.max()) == pytest.approx((0.0, 20.0), abs=1e-9)
    assert loop.area == pytest.approx(layer.area, rel=1e-6)
    assert np.allclose(layer.centroid, [0, 0, 10], atol=1e-9)


def test_solid_cylinder_cut_by_coaxial_cylinder_inside_and_outside(App, Part):
    rod = Part.makeCylinder(6, 30, App.Vector(0, 0, -5))
    stack = cylindrical_sections(rod, [2.0, 5.999, 8.0])
    assert stack.layers[0].area == pytest.approx(2 * math.pi * 2 * 30, rel=1e-9)
    assert stack.layers[1].area == pytest.approx(2 * math.pi * 5.999 * 30, rel=1e-9)
    assert stack.layers[2].is_empty


def test_off_axis_box_gives_one_loop_per_island_in_the_unrolled_plane(App, Part):
    # The plate spans both sides of the axis: two arcs of half-angle asin(2/3) at radius 3.
    plate = Part.makeBox(20, 4, 10, App.Vector(-10, -2, 0))
    layer = cylindrical_sections(plate, [3.0]).layers[0]
    expected_arc = 2 * 3 * math.asin(2 / 3)
    assert layer.area == pytest.approx(2 * expected_arc * 10, rel=1e-9)
    assert len(layer.loops) == 2, "no island is split at the cylinder's seam"
    for loop in layer.loops:
        width = loop.points[:, 0].max() - loop.points[:, 0].min()
        assert width == pytest.approx(expected_arc, rel=1e-6)
        assert loop.area == pytest.approx(expected_arc * 10, rel=1e-5)


def test_roll_inverts_unroll(App):
    axis = CylinderAxis.make((1, 2, 3), (0.2, -0.4, 1.0))
    unrolled = np.array([[0.0, 0.0], [3.0, 1.0], [10.0, -2.0]])
    points = axis.roll(unrolled, 4.0)
    assert np.allclose(axis.unroll(points, 4.0), unrolled, atol=1e-12)
    radial = points - axis.point - np.outer((points - axis.point) @ axis.frame.n, axis.frame.n)
    assert np.allclose(np.linalg.norm(radial, axis=1), 4.0)


def test_bad_radii_are_clear_errors(Part):
    with pytest.raises(GeometryError, match="positive"):
        cylindrical_sections(Part.makeBox(1, 1, 1), [0.0])
    with pytest.raises(GeometryError, match="at least one"):
        cylindrical_sections(Part.makeBox(1, 1, 1), [])
