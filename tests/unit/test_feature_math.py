"""Pure maths of conformal features and mandrel builds (no FreeCAD)."""
from __future__ import annotations

import math

import numpy as np
import pytest
from shapely.geometry import LineString, Polygon, box

from freecad_conformal.errors import GeometryError, PlanError
from freecad_conformal.paths.features.channels import narrowest, straight_channels
from freecad_conformal.paths.features.fill import contours, long_axis_angle, zigzag
from freecad_conformal.paths.features.outlines import region_from_rings, svg_path_rings
from freecad_conformal.paths.features.feeds import rod_settings
from freecad_conformal.paths.features.rods import collisions, published_min_angle, sphere_layout
from freecad_conformal.jobs.mandrel import (
    band_inclination, compensated_extrusion, corrected_feed, sample_joint_line, stitch_across_seam)
from freecad_conformal.process.curing_fit import CurePoint
from freecad_conformal.process.process_settings import ProcessSettings
from freecad_conformal.process.tools import Envelope, Tool, UvGuide


def _tool(body: float, tip_length: float = 0.0, w_deg: float = 60.0) -> Tool:
    return Tool(id="probe", name="probe", kind="uv_light_guide", diameter=0.3,
                envelope=Envelope(max(0.3, body if tip_length == 0 else 0.3), tip_length, body, 40.0),
                spec=UvGuide(0.3, 0.2, [0.5]), max_tilt=math.radians(w_deg))


def test_band_inclination_and_compensation():
    assert band_inclination(8.0, 10.0) == pytest.approx(math.atan(8.0 / (20.0 * math.pi)))
    assert math.degrees(band_inclination(8.0, 10.0)) == pytest.approx(7.2561, abs=1e-4)
    # first layer (Ri = R0): no compensation
    assert compensated_extrusion(3.0, 4.0, 10.0, 10.0, 0.5) == pytest.approx(2.5)
    # Ri = 2 R0: the around component counts double
    assert compensated_extrusion(3.0, 4.0, 20.0, 10.0, 0.5) == pytest.approx(0.5 * math.hypot(8, 3))
    assert corrected_feed(0.0, 10.0, 20.0, 10.0, 2000.0) == pytest.approx(1000.0)
    assert corrected_feed(5.0, 0.0, 20.0, 10.0, 2000.0) == pytest.approx(2000.0)
    with pytest.raises(PlanError):
        band_inclination(0.0, 10.0)


def test_joint_line_sampling_keeps_corners_and_chord():
    corners = np.array([[0.0, 0.0, 10.0], [4 * math.pi, 8.0, 10.0], [4 * math.pi, 9.0, 11.0]])
    samples = sample_joint_line(corners, tolerance=0.01)
    assert np.allclose(samples[0], corners[0]) and np.allclose(samples[-1], corners[-1])
    step = np.abs(np.diff(samples[:, 0])).max()
    assert 10.0 * (1 - math.cos(step / 2)) <= 0.01 + 1e-12
    assert any(np.allclose(s, corners[1]) for s in samples)


def test_seam_pieces_join_into_one_band():
    period = 20.0
    left = Polygon([(0, 0), (5, 0), (5, 2), (0, 2)])
    right = Polygon([(15, 1), (20, 1), (20, 3), (15, 3)]).difference(box(15, 2.5, 16, 3))
    pieces = stitch_across_seam([left, right], period)
    assert len(pieces) == 1
    assert pieces[0].area == pytest.approx(left.area + right.area, rel=1e-3)


def test_published_rule_and_ring_counts():
    a, radius, length, head = 1.2, 20.0, 3.0, 3.0
    base = radius - length
    expected = math.atan(a / (2 * base)) + math.asin(2 * head / math.sqrt(a * a + 4 * base * base))
    assert published_min_angle(a, radius, length, head) == pytest.approx(expected)
    layout = sphere_layout((0, 0, 0), (0, 0, 1), radius, 3.0, a, length, math.radians(60))
    theta = 3.0 / radius
    assert len(layout.rings) - 1 == math.floor(math.radians(60) / theta)     # (v)
    for ring in layout.rings[1:]:
        assert ring.tilt == pytest.approx(ring.index * theta)                # (ii)
        assert ring.count == math.floor(2 * math.pi * radius * math.sin(ring.tilt) / 3.0)  # (iii)
        assert ring.step == pytest.approx(2 * math.pi / ring.count)         # (iv)
    np.testing.assert_allclose(np.linalg.norm(layout.bases, axis=1), radius)
    with pytest.raises(PlanError, match="beyond the tool's W"):
        sphere_layout((0, 0, 0), (0, 0, 1), radius, 3.0, a, length, math.radians(60), rings=8)


def _two_rods(theta, radius, a, length):
    layout = sphere_layout((0, 0, 0), (0, 0, 1), radius, radius * theta, a, length,
                           math.radians(60), rings=1)
    keep = np.array([0, 1])
    layout.bases, layout.axes, layout.ring_of = layout.bases[keep], layout.axes[keep], layout.ring_of[keep]
    return layout


def test_collision_test_against_closed_form_and_published_rule():
    """A cylindrical envelope of diameter D standing on the surface clears a neighbour rod of
    diameter a when the base points are (D + a)/2 apart: θ = 2·asin((D + a) / (4R))."""
    radius, a, length, head = 20.0, 1.2, 3.0, 3.0
    tool = _tool(head)
    low, high = 0.01, 0.5
    for _ in range(40):
        mid = 0.5 * (low + high)
        if collisions(_two_rods(mid, radius, a, length), tool):
            low = mid
        else:
            high = mid
    closed = 2 * math.asin((head + a) / (4 * radius))
    assert high == pytest.approx(closed, abs=1e-6)
    # the published rule (i) is safe here, and about twice as strict as needed
    published = published_min_angle(a, radius, length, head)
    assert not collisions(_two_rods(published, radius, a, length), tool)
    assert 1.5 < published / closed < 2.5


def test_rod_feeds_from_the_point_curing_fit():
    tool = _tool(3.0)
    tool.settings["resin"] = ProcessSettings(power=0.495, rod_points=[CurePoint(0.495, 0.75, 1.2)],
                                             line_points=[CurePoint(0.495, 2.532, 0.2)])
    rod, = rod_settings(tool, [1.2])
    assert rod.feed == pytest.approx(45.0)                      # the published point
    thick, thin = rod_settings(tool, [1.4, 1.0])
    assert thick.feed < 45.0 < thin.feed                        # slower: thicker rod
    assert thin.energy_per_mm == pytest.approx(0.495 / (thin.feed / 60))
    with pytest.raises(PlanError, match="faster than 213.36 mm/min"):
        rod_settings(tool, [1.2, 0.5])
    bare = _tool(3.0)
    with pytest.raises(PlanError, match="neither calibration points nor a feed"):
        rod_settings(bare, [1.2])


def test_svg_subset():
    rings = svg_path_rings("M0 0 L10 0 L10 10 H0 Z M2 2 l2 0 0 2 -2 0 z", flip_y=False)
    assert region_from_rings(rings).area == pytest.approx(96.0)
    k = 4 * (math.sqrt(2) - 1) / 3 * 5       # four cubics approximate a circle of radius 5
    circle = (f"M5 0 C5 {k} {k} 5 0 5 C{-k} 5 -5 {k} -5 0 C-5 {-k} {-k} -5 0 -5 "
              f"C{k} -5 5 {-k} 5 0 Z")
    assert region_from_rings(svg_path_rings(circle)).area == pytest.approx(25 * math.pi, rel=1e-3)
    quad = svg_path_rings("M0 0 Q5 10 10 0 Z", flip_y=False)
    assert region_from_rings(quad).area == pytest.approx(2 / 3 * 10 * 5, rel=1e-3)
    with pytest.raises(GeometryError, match="unsupported"):
        svg_path_rings("M0 0 A5 5 0 0 1 10 0 Z")


def test_zigzag_and_contours():
    region = box(0, 0, 10, 4)
    lines = zigzag(region, 1.0)
    assert len(lines) == 1                          # one connected boustrophedon
    assert len(lines[0]) == 8                       # 4 rows of 2 points
    assert all(region.buffer(1e-9).covers(LineString(l)) for l in lines)
    assert long_axis_angle(region) % math.pi == pytest.approx(0.0, abs=1e-9)
    rings = contours(region, 1.0)
    assert len(rings) == 2
    assert Polygon(rings[0]).area == pytest.approx(9 * 3)
    with pytest.raises(PlanError, match="too thin"):
        zigzag(box(0, 0, 10, 0.2), 1.0, inset=0.5)


def test_channel_widths():
    footprint, gaps = straight_channels(3, 15.0, 1.0, 1.5)
    assert narrowest(gaps) == pytest.approx(1.0, abs=1e-4)
    assert narrowest(footprint.difference(gaps)) == pytest.approx(1.5, abs=1e-4)
    assert footprint.bounds[3] - footprint.bounds[1] == pytest.approx(3 * 1.0 + 4 * 1.5)
