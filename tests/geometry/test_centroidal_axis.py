"""Centroidal axis: break links are the real turns only; the blind spot is flagged."""
from __future__ import annotations

import numpy as np
import pytest

from freecad_conformal.geometry import samples
from freecad_conformal.geometry.centroidal_axis import centroidal_axis


@pytest.mark.parametrize("method", ["true-direction", "published"])
def test_hinge_breaks_only_where_the_lugs_turn(method):
    axis = centroidal_axis(samples.hinge(), method=method)
    breaks = axis.break_links()
    assert len(breaks) == 2
    assert all(link.kind == "turn" for link in breaks)
    directions = sorted(tuple(np.round(axis.link_direction(l), 6) + 0.0) for l in breaks)
    assert directions == [(0, 1, 0), (0, 1, 0)]


def test_inclined_rod_has_no_break_when_followed():
    axis = centroidal_axis(samples.inclined_rod(tilt_deg=30.0), method="true-direction")
    assert axis.break_links() == []


def test_l_block_breaks_once_towards_the_arm():
    axis = centroidal_axis(samples.l_block())
    (link,) = axis.break_links()
    np.testing.assert_allclose(axis.link_direction(link), [1, 0, 0], atol=1e-12)


def test_wide_cap_on_a_column_is_flagged_as_a_blind_spot(Part, App):
    column = Part.makeBox(10, 10, 30)
    cap = Part.makeBox(40, 40, 5, App.Vector(-15, -15, 30))
    part = column.fuse(cap).removeSplitter()
    axis = centroidal_axis(part)
    spots = axis.blind_spots()
    assert len(spots) == 1
    start, end = axis.nodes[spots[0].start], axis.nodes[spots[0].end]
    # The centroid stays on the column's axis: the turn test has nothing to see.
    assert np.linalg.norm((end.point - start.point)[:2]) < 1e-6
    assert start.point[2] < 30 < end.point[2] + axis.step
    assert end.area / start.area == pytest.approx(16.0)
    assert axis.to_dict()["blind_spots"][0]["area_ratio"] == pytest.approx(16.0)


def test_plain_column_has_no_blind_spot(Part):
    assert centroidal_axis(Part.makeBox(10, 10, 30)).blind_spots() == []


def test_a_part_laid_flat_is_stepped_at_its_length_not_its_thickness(App, Part):
    # A 100 × 20 × 5 mm bar with a 20 mm lug standing at one end, searched from +Z: the
    # step is 100/40 mm (5/40 mm would take 800 sections to run its length).
    bar = Part.makeBox(100, 20, 5).fuse(Part.makeBox(10, 20, 20, App.Vector(90, 0, 5)))
    axis = centroidal_axis(bar.removeSplitter())
    assert axis.step == pytest.approx(100 / 40)
    # Up through the bar and the lug (25 mm) in 2.5 mm steps, ending in the lug.
    assert len(axis.nodes) <= 12
    assert axis.nodes[-1].point[0] == pytest.approx(95.0, abs=1e-6)
