"""Bead models, PrusaSlicer's fill rules (overlap, solid below an area, small perimeters)
and the cooling slowdown."""
from __future__ import annotations

import math

import numpy as np
import pytest
from shapely.geometry import box

from freecad_conformal.errors import PlanError
from freecad_conformal.paths.assemble import (SMALL_PERIMETER_LENGTH, Feeds, PathSettings,
                                              _layer_feeds)
from freecad_conformal.paths.bead import bead_area, bead_spacing
from freecad_conformal.paths.fill2d import FillSettings, fill_layer
from freecad_conformal.paths.map3d import Path3D


@pytest.mark.parametrize("model", ["rounded", "rectangular"])
@pytest.mark.parametrize("width, height", [(0.45, 0.2), (0.4, 0.1), (0.6, 0.3)])
def test_beads_at_their_spacing_fill_the_slab(model, width, height):
    assert bead_area(width, height, model) / bead_spacing(width, height, model) == pytest.approx(height)


def test_rounded_bead_is_prusaslicers():
    # PrusaSlicer 2.5 at 0.45 x 0.2 mm: (w - h) h + pi h^2 / 4 and spacing w - h (1 - pi/4)
    assert bead_area(0.45, 0.2) == pytest.approx(0.05 + math.pi * 0.01)
    assert bead_spacing(0.45, 0.2) == pytest.approx(0.45 - 0.2 * (1 - math.pi / 4))
    assert bead_spacing(0.45, None) == 0.45


def test_bad_bead_model_or_size_is_refused():
    with pytest.raises(PlanError, match="bead model 'oval'"):
        bead_area(0.4, 0.2, "oval")
    with pytest.raises(PlanError, match="positive"):
        bead_spacing(0.4, 0.0)


def _infill_length(region, **settings) -> dict[str, float]:
    paths = fill_layer(region, FillSettings(bead_width=0.45, perimeters=2, density=0.2, angle=0.0,
                                            **settings), height=0.2)
    lengths: dict[str, float] = {}
    for path in paths:
        lengths[path.role] = lengths.get(path.role, 0.0) + path.length
    return lengths


def test_small_sparse_regions_are_printed_solid():
    """An 8 x 8 mm section leaves ~39 mm2 inside two perimeters: under 70 mm2 it is solid,
    under a 10 mm2 threshold it is sparse."""
    solid = _infill_length(box(0, 0, 8, 8))
    assert "infill" not in solid and solid["solid_infill"] > 0
    sparse = _infill_length(box(0, 0, 8, 8), solid_below_area=10.0)
    assert "solid_infill" not in sparse and sparse["infill"] > 0
    big = _infill_length(box(0, 0, 30, 30))
    assert "solid_infill" not in big


def test_the_small_area_rule_measures_the_fill_area_not_where_lines_end():
    """A 9.9 mm square's fill area (inside the perimeters, reaching 25 % into them) is 71
    mm², over the 70 mm² threshold: sparse, as PrusaSlicer's fill surface; where its lines
    end (half a spacing further in) it is 64 mm², which must not count."""
    spacing = bead_spacing(0.45, 0.2)
    side = 9.9 - 2 * (0.225 + 1.25 * spacing)
    assert side * side > 70.0 > (side - spacing) ** 2
    assert "solid_infill" not in _infill_length(box(0, 0, 9.9, 9.9))


def test_infill_reaches_into_the_perimeters_by_the_overlap():
    inner = fill_layer(box(0, 0, 30, 30), FillSettings(bead_width=0.45, perimeters=2, density=1.0,
                                                       angle=0.0, alternate=False), height=0.2)
    lines = np.vstack([p.points for p in inner if p.role == "infill"])
    spacing = bead_spacing(0.45, 0.2)
    # The innermost perimeter's inner edge lies at w/2 + 1.5 spacing; a line's bead ends
    # half a spacing past its end point and reaches 25 % of a spacing into that perimeter,
    # as its sides do (PrusaSlicer's line ends: 0.75 spacing inside the ring's centre line).
    edge = 0.225 + 1.5 * spacing + 0.25 * spacing
    assert lines[:, 0].min() == pytest.approx(edge, abs=1e-6)
    none = fill_layer(box(0, 0, 30, 30), FillSettings(bead_width=0.45, perimeters=2, density=1.0,
                                                      angle=0.0, alternate=False, infill_overlap=0.0),
                      height=0.2)
    lines = np.vstack([p.points for p in none if p.role == "infill"])
    assert lines[:, 0].min() == pytest.approx(edge + 0.25 * spacing, abs=1e-6)


def _loop(side: float, role: str = "external_perimeter") -> Path3D:
    square = np.array([[0, 0, 0], [side, 0, 0], [side, side, 0], [0, side, 0], [0, 0, 0]], float)
    return Path3D(square, np.array([0.0, 0, 1]), role, 0, 0, 0.2, closed=True)


def test_small_perimeter_loops_are_slow():
    feeds = Feeds(external_perimeter=1800.0, small_perimeter=900.0)
    assert feeds.for_path(_loop(8.0)) == 900.0                    # 32 mm loop
    assert feeds.for_path(_loop(SMALL_PERIMETER_LENGTH / 4 + 0.1)) == 1800.0
    infill = Path3D(_loop(8.0).points, np.array([0.0, 0, 1]), "infill", 0, 0, 0.2)
    assert feeds.for_path(infill) == feeds.infill


def test_cooling_caps_feeds_so_the_layer_takes_the_minimum_time():
    settings = PathSettings(feeds=Feeds(external_perimeter=3600.0, perimeter=3600.0, infill=6000.0,
                                        solid_infill=1200.0, small_perimeter=3600.0),
                            min_layer_time=5.0, min_speed=600.0)
    paths = [_loop(20.0, "perimeter"), _loop(20.0)]
    paths[1].points = paths[1].points + [1.0, 0, 0]
    feeds = _layer_feeds(paths, settings)
    travel = 60.0 * 1.0 / settings.feeds.travel
    seconds = travel + sum(60.0 * p.length / f for p, f in zip(paths, feeds))
    assert seconds == pytest.approx(5.0, rel=1e-6)
    assert feeds[0] == feeds[1] < 3600.0                          # one common cap
    slow = PathSettings(feeds=settings.feeds, min_layer_time=60.0, min_speed=600.0)
    assert _layer_feeds(paths, slow) == [600.0, 600.0]            # never below the minimum speed
    quick = PathSettings(feeds=settings.feeds, min_layer_time=1.0)
    assert _layer_feeds(paths, quick) == [3600.0, 3600.0]


@pytest.mark.parametrize("field, value, message", [("bead_model", "oval", "bead model"),
                                                   ("infill_overlap", 1.5, "infill overlap"),
                                                   ("solid_below_area", -1.0, "solid infill area")])
def test_bad_fill_rules_are_refused(field, value, message):
    with pytest.raises(PlanError, match=message):
        fill_layer(box(0, 0, 10, 10), FillSettings(**{field: value}))


def test_solid_lines_spread_over_the_fill_area_with_wider_beads():
    """Solid infill (PrusaSlicer's adjusted solid spacing): as many whole spacings as fit
    the fill area's width, widened to span it exactly, each bead as much wider; the first
    and last rows lie half a pitch inside the fill area, and the beads carry its area x h."""
    from freecad_conformal.paths.fill2d import fill_area

    settings = FillSettings(bead_width=0.45, perimeters=2, density=0.2, angle=0.0,
                            alternate=False)
    region = box(0, 0, 30, 9.3)
    spacing = bead_spacing(0.45, 0.2)
    fill = fill_area(region, 2, 0.45, spacing, settings.infill_overlap)
    low, high = fill.bounds[1], fill.bounds[3]
    count = int((high - low) // spacing)
    pitch = (high - low) / count
    assert spacing < pitch < 1.2 * spacing          # this width does need spreading
    lines = [p for p in fill_layer(region, settings, solid=region, height=0.2)
             if p.role == "solid_infill"]
    rows = np.unique(np.round(np.concatenate([p.points[:, 1] for p in lines]), 9))
    assert len(rows) == count
    assert np.allclose(np.diff(rows), pitch)
    assert rows[0] == pytest.approx(low + pitch / 2) and rows[-1] == pytest.approx(high - pitch / 2)
    assert all(p.width == pytest.approx(0.45 + pitch - spacing) for p in lines)
    along = sum(p.length for p in lines)
    carried = along * bead_area(lines[0].width, 0.2)
    assert carried == pytest.approx(fill.area * 0.2, rel=0.02)


def test_infill_at_full_density_is_spread_like_solid_and_sparse_is_not():
    """100 % infill spreads its rows over the area as solid infill does (PrusaSlicer's full
    infill); sparse rows keep the global grid (no bead width of their own)."""
    region = box(0, 0, 30, 9.3)
    full = fill_layer(region, FillSettings(bead_width=0.45, perimeters=2, density=1.0,
                                           angle=0.0, alternate=False), height=0.2)
    lines = [p for p in full if p.role == "infill"]
    assert lines and all(p.width is not None and p.width > 0.45 for p in lines)
    sparse = fill_layer(box(0, 0, 30, 30), FillSettings(bead_width=0.45, perimeters=2,
                                                        density=0.2, angle=0.0), height=0.2)
    assert all(p.width is None for p in sparse if p.role == "infill")
