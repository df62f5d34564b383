"""2D fills: perimeters, holes, zigzag infill, fewest turns, seams, order, bad settings."""
from __future__ import annotations

import math

import numpy as np
import pytest
from shapely.geometry import LineString, MultiPolygon, Point, Polygon, box

from freecad_conformal.errors import PlanError
from freecad_conformal.paths.fill2d import (FillSettings, fewest_turns_angle, fill_layer,
                                            perimeter_rings, zigzag)

WIDTH = 0.4


def _plate_with_hole() -> Polygon:
    return box(0, 0, 40, 30).difference(Point(25, 15).buffer(5, quad_segs=64))


def test_perimeters_are_offset_by_bead_widths():
    depths = perimeter_rings(box(0, 0, 20, 10), WIDTH, 3)
    assert len(depths) == 3
    for k, rings in enumerate(depths):
        (ring,) = rings
        xs, ys = ring[:, 0], ring[:, 1]
        inset = (k + 0.5) * WIDTH
        assert xs.min() == pytest.approx(inset) and ys.max() == pytest.approx(10 - inset)


def test_holes_get_their_own_perimeters_and_stay_empty():
    plate = _plate_with_hole()
    paths = fill_layer(plate, FillSettings(bead_width=WIDTH, perimeters=2, density=1.0))
    loops = [p for p in paths if p.closed]
    assert len(loops) == 4          # outer and hole boundary, two perimeters each
    hole = Point(25, 15).buffer(5 - 0.5 * WIDTH + 1e-6)
    for path in paths:
        assert not LineString(path.points).intersects(hole.buffer(-1e-3))


def test_solid_fill_deposits_the_area():
    """Bead width × length of a solid layer matches the region's area (connectors add a bit)."""
    plate = _plate_with_hole()
    paths = fill_layer(plate, FillSettings(bead_width=WIDTH, perimeters=2, density=1.0))
    covered = sum(p.length for p in paths) * WIDTH
    assert covered == pytest.approx(plate.area, rel=0.03)


def test_sparse_density_scales_infill_length():
    square = box(0, 0, 30, 30)
    def infill_length(density):
        paths = fill_layer(square, FillSettings(bead_width=WIDTH, perimeters=0, density=density,
                                                angle=0.0, alternate=False))
        return sum(p.length for p in paths if p.role == "infill")
    ratio = infill_length(0.2) / infill_length(0.4)
    assert ratio == pytest.approx(0.5, rel=0.08)


def test_fewest_turns_runs_along_the_long_side():
    strip = box(0, 0, 50, 5)
    assert fewest_turns_angle(strip, 2.0) == pytest.approx(0.0)
    tall = box(0, 0, 5, 50)
    assert fewest_turns_angle(tall, 2.0) == pytest.approx(math.pi / 2)


def test_zigzag_connectors_stay_inside():
    """An L-shaped area: every infill polyline lies inside it (slack of a bead fraction)."""
    ell = box(0, 0, 30, 10).union(box(0, 0, 10, 30))
    lines = zigzag(ell, 1.0, 0.0, WIDTH, "infill")
    guard = ell.buffer(0.05 * WIDTH)
    assert lines and all(guard.covers(LineString(p.points)) for p in lines)
    assert len(lines) < 10          # linked into zigzags, not one path per scan line


def test_solid_area_gets_dense_lines():
    square = box(0, 0, 20, 20)
    skin = MultiPolygon([box(0, 0, 10, 20)])
    paths = fill_layer(square, FillSettings(bead_width=WIDTH, perimeters=1, density=0.2), solid=skin)
    roles = {p.role for p in paths}
    assert {"solid_infill", "infill", "external_perimeter"} <= roles
    dense = sum(p.length for p in paths if p.role == "solid_infill") * WIDTH
    assert dense == pytest.approx(20 * 10 - 20 * WIDTH - 10 * WIDTH, rel=0.08)


def test_seams():
    square = box(0, 0, 10, 10)
    aligned = fill_layer(square, FillSettings(perimeters=1, density=0.0, seam="aligned"))
    assert aligned[0].points[0][1] == pytest.approx(10 - 0.2)   # rearmost (largest v)
    near = fill_layer(square, FillSettings(perimeters=1, density=0.0, seam="nearest"),
                      position=np.array([10.0, 0.0]))
    np.testing.assert_allclose(near[0].points[0], [9.8, 0.2])
    assert np.allclose(near[0].points[0], near[0].points[-1])    # loops close


def test_islands_in_nearest_order_and_external_perimeter_last():
    islands = MultiPolygon([box(0, 0, 5, 5), box(100, 0, 105, 5), box(20, 0, 25, 5)])
    paths = fill_layer(islands, FillSettings(perimeters=2, density=0.2))
    xs = [p.points[:, 0].mean() for p in paths if p.role == "external_perimeter"]
    assert xs == sorted(xs)
    first_island = [p.role for p in paths if p.points[:, 0].max() < 6]
    assert first_island.index("perimeter") < first_island.index("external_perimeter")


@pytest.mark.parametrize("field, value", [("bead_width", 0.0), ("bead_width", -1.0),
                                          ("perimeters", -1), ("density", 1.5), ("seam", "left")])
def test_bad_settings_are_refused(field, value):
    settings = FillSettings(**{field: value})
    with pytest.raises(PlanError, match=field.split("_")[0].rstrip("s")):
        fill_layer(box(0, 0, 10, 10), settings)


def test_zigzag_rows_link_along_the_boundary_where_a_straight_connector_would_leave():
    """An annulus: rows ending on the hole cannot be linked straight across it, nor around a
    disc's rim with dense lines; along the boundary they link into a few chains, inside."""
    ring = Point(0, 0).buffer(15, quad_segs=64).difference(Point(0, 0).buffer(6, quad_segs=64))
    lines = zigzag(ring, 2.0, 0.0, WIDTH, "infill")
    assert len(lines) <= 3
    guard = ring.buffer(0.05 * WIDTH)
    assert all(guard.covers(LineString(p.points)) for p in lines)
    dense = zigzag(Point(0, 0).buffer(15, quad_segs=64), 0.4, 0.3, WIDTH, "solid_infill")
    assert len(dense) <= 3


def test_a_self_touching_outline_is_repaired_before_filling():
    """A bow-tie outline (the two triangles meet at one point) is an invalid polygon; GEOS
    raises topology errors on it. The fill repairs it and fills both triangles."""
    from shapely.geometry import Polygon

    from freecad_conformal.paths.fill2d import FillSettings, fill_layer

    bow_tie = Polygon([(0, 0), (10, 10), (10, 0), (0, 10)])
    assert not bow_tie.is_valid
    paths = fill_layer(bow_tie, FillSettings(bead_width=0.4, perimeters=1, density=0.5))
    perimeters = [p for p in paths if p.role == "external_perimeter"]
    assert len(perimeters) == 2
    xs = np.concatenate([p.points[:, 0] for p in perimeters])
    assert xs.min() < 2.0 and xs.max() > 8.0              # both triangles are printed


def test_fewest_turns_from_the_boundary_matches_counting_the_scan_pieces():
    """The direction chosen from the boundary's crossings has as few zigzag pieces as the
    best of the candidates counted piece by piece by the scan."""
    import random

    import shapely

    from freecad_conformal.paths.fill2d import _scan_segments, fewest_turns_angle
    from freecad_conformal.paths.scan import CANDIDATE_ANGLES

    rng = random.Random(7)
    for _ in range(60):
        points = [(rng.uniform(0, 50), rng.uniform(0, 50)) for _ in range(rng.randint(3, 9))]
        blob = Polygon(points).convex_hull.union(
            Point(rng.uniform(0, 50), rng.uniform(0, 50)).buffer(rng.uniform(2, 10)))
        area = shapely.make_valid(blob).difference(Point(25, 25).buffer(rng.uniform(0, 8)))
        for spacing in (0.45, 2.0):
            pieces = [sum(len(row) for row in _scan_segments(area, spacing, a))
                      for a in CANDIDATE_ANGLES]
            chosen = CANDIDATE_ANGLES.index(fewest_turns_angle(area, spacing))
            assert pieces[chosen] == min(pieces), (pieces, chosen)


def test_bridge_infill_fills_the_solid_over_sparse_apart():
    """A 30 x 20 mm solid layer whose left half lies over sparse infill: that half is laid as
    bridge infill, the rest as solid infill, each only inside its own area; without a bridge
    area the whole is solid infill as before."""
    region = box(0, 0, 30, 20)
    settings = FillSettings(bead_width=WIDTH, perimeters=2)
    bridge = box(0, 0, 15, 20)
    paths = fill_layer(region, settings, solid=region, bridge=bridge)
    roles = {p.role for p in paths}
    assert {"bridge_infill", "solid_infill"} <= roles and "infill" not in roles
    for path in paths:
        if path.role in ("bridge_infill", "solid_infill"):
            line = LineString(path.points)
            inside = bridge if path.role == "bridge_infill" else box(15, 0, 30, 20)
            assert inside.buffer(WIDTH).contains(line), path.role
    length = {role: sum(p.length for p in paths if p.role == role) for role in roles}
    assert length["bridge_infill"] == pytest.approx(length["solid_infill"], rel=0.1)
    plain = fill_layer(region, settings, solid=region)
    assert {p.role for p in plain} == {"external_perimeter", "perimeter", "solid_infill"}
    total = sum(p.length for p in plain if p.role == "solid_infill")
    assert length["bridge_infill"] + length["solid_infill"] == pytest.approx(total, rel=0.05)


def _random_areas(count: int, seed: int):
    import random

    import shapely

    rng = random.Random(seed)
    for _ in range(count):
        points = [(rng.uniform(0, 50), rng.uniform(0, 50)) for _ in range(rng.randint(3, 9))]
        blob = Polygon(points).convex_hull.union(
            Point(rng.uniform(0, 50), rng.uniform(0, 50)).buffer(rng.uniform(2, 10)))
        yield shapely.make_valid(blob).difference(Point(25, 25).buffer(rng.uniform(0, 8))), rng


def test_scan_pieces_are_the_lines_clipped_to_the_area():
    """Against GEOS clipping each scan line to the area (on valid areas, where it is right):
    the same rows, the same pieces."""
    from freecad_conformal.paths.scan import scan_pieces

    for area, rng in _random_areas(40, seed=11):
        spacing, angle = rng.choice((0.45, 1.3)), rng.uniform(0, math.pi)
        pieces, first = scan_pieces(area, spacing, angle)
        turned = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
        expected = []
        for row in range(-2, int(200 / spacing)):
            y = (first + row) * spacing
            line = LineString(np.array([(-200.0, y), (200.0, y)]) @ turned.T)
            clipped = line.intersection(area)
            for piece in getattr(clipped, "geoms", [clipped]):
                if piece.geom_type == "LineString" and piece.length >= 1e-6:
                    x = np.asarray(piece.coords) @ turned
                    expected.append((row, x[:, 0].min(), x[:, 0].max()))
        got = sorted(map(tuple, pieces))
        assert len(got) == len(expected)
        np.testing.assert_allclose(got, sorted(expected), atol=1e-7)


def test_scan_pieces_stay_inside_an_area_that_turning_makes_self_intersecting():
    """A sliced_cylinder layer's infill area: turned by the infill angle, its ring crossed
    itself, and GEOS's clip returned the 194 pieces outside it (infill laid beside the
    part) instead of the 97 inside."""
    from pathlib import Path

    import shapely

    from freecad_conformal.paths.scan import scan_pieces

    text = (Path(__file__).parent / "data" / "scan_area_turned_self_intersecting.wkt").read_text()
    area = shapely.from_wkt(text)
    spacing, angle = 1.7853981633974452, 4.188790204786391
    pieces, first = scan_pieces(area, spacing, angle)
    cos, sin = math.cos(angle), math.sin(angle)
    y = (first + pieces[:, 0]) * spacing
    middle = 0.5 * (pieces[:, 1] + pieces[:, 2])
    points = shapely.points(middle * cos - y * sin, middle * sin + y * cos)
    assert len(pieces) == 97 and shapely.contains(area, points).all()
    assert (pieces[:, 2] - pieces[:, 1]).sum() == pytest.approx(area.area / spacing, rel=0.02)


def test_boundary_paths_read_in_a_batch_are_the_ones_read_point_by_point():
    """Zigzag links along the boundary: the rings' distances and positions read for all
    row ends at once give the same links as reading each point when it is needed."""
    from freecad_conformal.paths.fill2d import _Boundary

    area = box(0, 0, 20, 10).difference(Point(10, 5).buffer(3, 16))
    rng = np.random.default_rng(2)
    rings = [area.exterior, *area.interiors]
    points = [tuple(np.asarray(ring.interpolate(t, normalized=True).coords[0]).tolist())
              for ring in rings for t in rng.uniform(0, 1, 12)]
    batch, single = _Boundary(area), _Boundary(area)
    batch.locate(points)
    pairs = [(p, q) for p in points for q in points if p != q]
    assert any(single.path(p, q, 100.0) is not None for p, q in pairs)
    for p, q in pairs:
        assert batch.path(p, q, 6.0) == single.path(p, q, 6.0)


def test_connectors_read_in_a_batch_are_the_ones_read_one_by_one():
    """Whether a straight connector between two row ends stays in the area: read for all
    pairs of consecutive rows' ends at once, the same as asked one segment at a time."""
    from freecad_conformal.paths.fill2d import _Guard, _scan_segments

    area = box(0, 0, 20, 10).difference(Point(10, 5).buffer(3, 16))
    spacing = 0.4
    rows = _scan_segments(area, spacing, 0.3)
    guard = _Guard(area.buffer(0.02), rows, spacing)
    ends = [((x0, y), (x1, y)) for row in rows for x0, x1, y in row]
    pairs = [(p, q) for (p0, p1), (q0, q1) in zip(ends, ends[1:]) for p in (p0, p1)
             for q in (q0, q1)]
    assert guard._known and any(not v for v in guard._known.values())
    single = area.buffer(0.02)
    for p, q in pairs:
        assert guard.covers_link(p, q) == single.covers(LineString([p, q]))


@pytest.mark.parametrize("degrees", [30, 45, 60, 90])
def test_connectors_never_cross_a_hole_whatever_the_direction(degrees):
    """Zigzag connectors stay in the area at every infill direction, on an area away from
    the layer's origin: the connector test once read the unturned area against row ends in
    the scan-line frame, and 11 of 2,593 segments crossed the hole of such a square."""
    from freecad_conformal.paths.fill2d import zigzag

    area = box(-7, -10, 13, 10).difference(Point(3, 0).buffer(3, 32))
    paths = zigzag(area, 0.4, math.radians(degrees), 0.45, "solid_infill")
    inside = area.buffer(0.05 * 0.45)
    segments = [LineString([a, b]) for p in paths for a, b in zip(p.points[:-1], p.points[1:])]
    assert len(segments) > 100
    assert all(inside.covers(segment) for segment in segments)


def test_a_bridge_is_laid_from_anchor_to_anchor_else_across_its_shortest_span():
    """A 20 x 10 mm gap: between two pillars at its short ends its rows run along the 20 mm
    (the only rows with both ends carried); walled all round, or carried on one side only
    (a cantilever), across the 10 mm."""
    import math

    from shapely.geometry import MultiPolygon, box

    from freecad_conformal.paths.scan import anchored_cover, bridge_angle

    gap = box(10, 0, 30, 10)
    pillars = MultiPolygon([box(0, 0, 10, 10), box(30, 0, 40, 10)])
    walls = box(0, -10, 40, 20).difference(gap)
    one_side = box(0, 0, 10, 10)
    assert bridge_angle(gap, 0.4, pillars, 0.2) == 0.0
    assert bridge_angle(gap, 0.4, walls, 0.2) == pytest.approx(0.5 * math.pi)
    assert bridge_angle(gap, 0.4, one_side, 0.2) == pytest.approx(0.5 * math.pi)
    assert anchored_cover(gap, 0.4, 0.0, pillars, 0.2).area == pytest.approx(200.0)
    # across, only the rows beside the pillars' faces rest on them
    assert anchored_cover(gap, 0.4, 0.5 * math.pi, pillars, 0.2).area <= 2 * 0.4 * 10 + 1e-9
