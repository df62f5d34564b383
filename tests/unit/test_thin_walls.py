"""Thin walls: features narrower than a bead get one bead along their middle."""
from __future__ import annotations

import numpy as np
import pytest
import shapely
from shapely.geometry import LineString, Point, Polygon, box

from freecad_conformal.paths.fill2d import MITRE_LIMIT, FillSettings, fill_layer, inset
from freecad_conformal.paths.thin_walls import MIN_BEAD_SHARE, MIN_WIDTH_SHARE, thin_wall_beads

WIDTH = 0.4


def beads_of(island):
    return thin_wall_beads(island, WIDTH, inset(island, 0.5 * WIDTH), MITRE_LIMIT)


def test_a_wall_narrower_than_the_bead_gets_one_closed_bead_along_its_middle():
    """A 0.3 mm box wall under a 0.4 mm bead: no perimeter fits, so it was left out; now
    one loop runs along its middle, 0.34 mm wide (no bead is laid narrower)."""
    wall = box(0, 0, 20, 20).difference(box(0.3, 0.3, 19.7, 19.7))
    (points, width, closed), = beads_of(wall)
    assert closed and np.allclose(points[0], points[-1])
    assert width == pytest.approx(MIN_BEAD_SHARE * WIDTH)
    middle = box(0.15, 0.15, 19.85, 19.85).exterior
    assert LineString(points).length == pytest.approx(middle.length, rel=0.01)
    assert shapely.hausdorff_distance(LineString(points), middle) < 0.05
    paths = fill_layer(wall, FillSettings(bead_width=WIDTH, perimeters=2, density=0.2))
    assert [(p.role, p.closed) for p in paths] == [("external_perimeter", True)]
    assert paths[0].width == pytest.approx(width)


@pytest.mark.parametrize("size", [(50, 40), (80, 50), (160, 20)])
def test_a_long_thin_wall_gets_one_bead_along_its_middle(size):
    """GEOS's triangulation is Delaunay only after a bounded number of edge-flip rounds:
    a 0.3 mm wall round a box 50 x 40 mm or larger got beads zigzagging across the wall in
    several pieces; long features are triangulated in tiles."""
    x, y = size
    wall = box(0, 0, x, y).difference(box(0.3, 0.3, x - 0.3, y - 0.3))
    (points, width, closed), = beads_of(wall)
    middle = box(0.15, 0.15, x - 0.15, y - 0.15).exterior
    assert closed and width == pytest.approx(MIN_BEAD_SHARE * WIDTH)
    assert LineString(points).length == pytest.approx(middle.length, rel=0.001)
    assert shapely.hausdorff_distance(LineString(points), middle) < 0.05


def test_tiles_are_not_cut_along_a_rib():
    """A grid of 0.3 mm ribs in a 0.3 mm wall round an 80 x 50 mm box, ribs under the tile
    grid's lines: a cut along a rib left one long edge no triangle crossed, and the beads
    came in 26 pieces a third too long. Each cut is made where it crosses the walls."""
    x, y = 80, 50
    ribs = [box(c - 0.15, 0, c + 0.15, y) for c in (10, 20, 30)] + [box(0, 19.85, x, 20.15)]
    grid = shapely.union_all([box(0, 0, x, y).difference(box(0.3, 0.3, x - 0.3, y - 0.3)), *ribs])
    middles = shapely.union_all([box(0.15, 0.15, x - 0.15, y - 0.15).exterior,
                                 *[LineString([(c, 0), (c, y)]) for c in (10, 20, 30)],
                                 LineString([(0, 20), (x, 20)])]).intersection(grid)
    beads = beads_of(grid)
    assert sum(LineString(points).length for points, _, _ in beads) == pytest.approx(
        middles.length, rel=0.005)
    assert max(shapely.distance(middles, shapely.points(points)).max()
               for points, _, _ in beads) < 0.06


def test_a_long_fin_gets_one_bead_along_its_middle():
    fin = box(0, 0, 10, 10).union(box(10, 4.85, 200, 5.15))
    (points, _, closed), = beads_of(fin)
    assert not closed and np.allclose(points[:, 1], 5.0, atol=1e-6)
    assert points[:, 0].max() == pytest.approx(200 - 0.15, abs=0.05)


def test_a_fin_on_a_block_gets_a_bead_from_the_block_to_its_end():
    fin = box(10, 4.82, 20, 5.18)                                     # 0.36 mm
    (points, width, closed), = beads_of(box(0, 0, 10, 10).union(fin))
    assert not closed and width == pytest.approx(0.36, abs=0.02)
    assert np.allclose(points[:, 1], 5.0, atol=1e-6)
    assert points[:, 0].max() == pytest.approx(20 - 0.18, abs=0.05)
    assert points[:, 0].min() < 10.0 + WIDTH
    # the bead stays on the fin: its sides reach the fin's sides, not beyond
    assert LineString(points).buffer(0.5 * width, cap_style="flat").difference(
        box(0, 0, 10, 10).union(fin)).area < 1e-3


def test_three_fins_meeting_make_three_beads_that_meet():
    tee = box(0, 0, 20, 0.3).union(box(9.85, 0, 10.15, 10))
    beads = beads_of(tee)
    assert len(beads) == 3
    ends = [tuple(np.round(p[k], 6)) for p, _, _ in beads for k in (0, -1)]
    assert max(ends.count(end) for end in ends) == 3      # one junction shared by all


@pytest.mark.parametrize("island", [box(0, 0, 10, 10), Point(0, 0).buffer(5, quad_segs=32),
                                    box(0, 0, 20, WIDTH * 1.2)])
def test_regions_every_bead_fits_get_none(island):
    assert beads_of(island) == []


def test_features_narrower_than_a_quarter_bead_or_shorter_than_two_are_left_out():
    hair = box(0, 0, 10, 10).union(box(10, 4.96, 20, 5.04))          # 0.08 mm
    stub = box(0, 0, 10, 10).union(box(10, 4.85, 10.5, 5.15))         # 0.5 mm long
    assert beads_of(hair) == [] and beads_of(stub) == []
    assert 0.08 < MIN_WIDTH_SHARE * WIDTH


def test_no_thin_walls_without_perimeters():
    wall = box(0, 0, 20, 20).difference(box(0.3, 0.3, 19.7, 19.7))
    assert fill_layer(wall, FillSettings(bead_width=WIDTH, perimeters=0, density=0.2)) == []


def test_a_tapering_fin_is_as_wide_as_its_middle():
    fin = Polygon([(10, 4.8), (20, 4.85), (20, 5.15), (10, 5.2)])     # 0.4 to 0.3 mm
    (_, width, _), = beads_of(box(0, 0, 10, 10).union(fin))
    assert 0.34 < width < 0.37


def test_without_constrained_delaunay_the_voronoi_axis_gives_the_same_bead(monkeypatch):
    """shapely < 2.1 (an Addon Manager install may have 2.0) has no constrained Delaunay
    triangulation: the axis then comes from a Voronoi diagram of the sampled outline."""
    wall = box(0, 0, 20, 20).difference(box(0.3, 0.3, 19.7, 19.7))
    fin = box(0, 0, 10, 10).union(box(10, 4.82, 20, 5.18))
    chordal = [beads_of(wall), beads_of(fin)]
    monkeypatch.delattr(shapely, "constrained_delaunay_triangles")
    for (points, width, closed), ((other, other_width, other_closed),) in zip(
            (beads_of(wall)[0], beads_of(fin)[0]), chordal):
        assert closed == other_closed and width == pytest.approx(other_width, abs=0.02)
        assert shapely.hausdorff_distance(LineString(points), LineString(other)) < 0.05


def test_where_the_triangulation_gives_up_the_voronoi_axis_gives_the_bead(monkeypatch):
    """GEOS's ear clipping raises on some slivers ("Unable to find a convex corner": a fan
    blade's trailing edge stopped its whole plan): the Voronoi axis is used there."""
    fin = box(0, 0, 10, 10).union(box(10, 4.82, 20, 5.18))
    (expected,) = beads_of(fin)

    def gives_up(*args, **kwargs):
        raise shapely.errors.GEOSException("IllegalStateException: Unable to find a convex corner")

    monkeypatch.setattr(shapely, "constrained_delaunay_triangles", gives_up)
    (points, width, closed), = beads_of(fin)
    assert closed == expected[2] and width == pytest.approx(expected[1], abs=0.02)
    assert shapely.hausdorff_distance(LineString(points), LineString(expected[0])) < 0.05


def test_the_voronoi_axis_takes_an_outline_in_parts():
    """A sliver's sampled outline may come back as several polygons."""
    from freecad_conformal.paths.thin_walls import _voronoi_axis

    parts = shapely.MultiPolygon([box(0, 0, 10, 0.3), box(0, 2, 10, 2.3)])
    pieces = _voronoi_axis(parts, WIDTH)
    assert pieces and all(parts.contains(piece) for piece in pieces)


def _clockwise(points: np.ndarray) -> bool:
    x, y = points[:, 0], points[:, 1]
    return float(np.dot(x[:-1], y[1:]) - np.dot(x[1:], y[:-1])) < 0.0


@pytest.mark.parametrize("feature", [
    box(0, 0, 20, 20).difference(box(0.3, 0.3, 19.7, 19.7)),                  # chordal axis
    Point(0, 0).buffer(10, 64).difference(Point(0, 0).buffer(9.7, 64)),       # round
    Point(3.3, -1.7).buffer(7, 90).difference(Point(3.3, -1.7).buffer(6.6, 90))])
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_a_closed_bead_runs_clockwise_as_the_outline_loops_do(feature, sign):
    """A closed bead ran whichever way its medial line came out (the square wall's
    counter-clockwise, the round ones' clockwise), and GEOS 3.13 and 3.14 gave a hollow
    ball's gap loops opposite ways: the same part, other G-code on FreeCAD 1.0. It now runs
    as the perimeter loops round an outline do (GEOS's buffers: clockwise), from the same
    start."""
    from shapely.geometry.polygon import orient

    from freecad_conformal.paths.thin_walls import medial_beads

    island = orient(feature, sign)
    (points, _, closed), = medial_beads([island], WIDTH)
    assert closed and _clockwise(points)
    # the loops round an outline, which the bead runs with
    outline = inset(orient(box(0, 0, 20, 20), sign), 0.5 * WIDTH)
    assert _clockwise(np.asarray(outline.exterior.coords))


def test_a_feature_met_again_moved_takes_the_beads_it_had_moved(monkeypatch):
    """A heat sink's fins: the same gap twelve times a layer, moved. Its axis is found once;
    the others take those beads moved (the first's own, bit for bit), another width or
    outline its own."""
    from freecad_conformal.paths import thin_walls

    monkeypatch.setattr(thin_walls, "_AXES", {})
    found: list[float] = []
    original = thin_walls.medial_lines

    def counted(feature, width):
        found.append(feature.bounds[0])
        return original(feature, width)

    monkeypatch.setattr(thin_walls, "medial_lines", counted)
    fin = box(0.0, 0.0, 0.3, 20.0)
    fins = [shapely.affinity.translate(fin, 3.3 * k + 0.123456789, 7.777777) for k in range(12)]
    beads = thin_walls.medial_beads(fins, WIDTH)
    assert len(found) == 1 and len(beads) == 12
    alone = thin_walls._feature_beads(fins[5], WIDTH)
    assert len(alone) == 1
    assert np.allclose(beads[5][0], alone[0][0], atol=1e-9) and beads[5][1:] == pytest.approx(
        alone[0][1:])
    first = thin_walls._feature_beads(fins[0], WIDTH)
    assert np.array_equal(beads[0][0], first[0][0])
    found.clear()
    thin_walls.medial_beads([fins[3]], WIDTH)                      # met before
    thin_walls.medial_beads([fins[3]], 0.5 * WIDTH)                # another width
    thin_walls.medial_beads([box(0.0, 0.0, 0.31, 20.0)], WIDTH)   # another outline
    assert len(found) == 2
