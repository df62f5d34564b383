"""Perimeter loops only where they have room, and gap fill where they have none: a wall is
filled neither over nor under, and the cost estimate lays what the fill lays."""
from __future__ import annotations

import numpy as np
import pytest
import shapely
from shapely.geometry import LineString, MultiPolygon, box

from freecad_conformal.geometry.frames import LayerFrame
from freecad_conformal.layers.model import Layer
from freecad_conformal.paths.assemble import PathSettings
from freecad_conformal.paths.bead import bead_area, bead_spacing
from freecad_conformal.paths.cost import Motion, layer_cost
from freecad_conformal.paths.fill2d import (MAX_WIDENING, FillSettings, fill_layer,
                                            island_walls, perimeter_walls)

WIDTH, HEIGHT = 0.4, 0.2
SPACING = bead_spacing(WIDTH, HEIGHT)
#: the beads' union may leave the round ends' corners of a square outline uncovered
CORNER_SHARE = 0.002
#: points per mm along a bead for the closest-neighbour check
SAMPLES_PER_MM = 50
#: how far (mm) a bead's simplified axis may stray from the middle (thin_walls simplifies
#: it by a sixteenth of a bead)
AXIS_SLACK = 0.03


def _tube(wall: float, x: float = 40.0, y: float = 30.0):
    return box(0, 0, x, y).difference(box(wall, wall, x - wall, y - wall))


def _fill(region, **settings):
    return fill_layer(region, FillSettings(bead_width=WIDTH, perimeters=2, density=0.2,
                                           **settings), height=HEIGHT)


def _laid(paths) -> float:
    return sum(p.length * bead_area(p.width or WIDTH, HEIGHT) for p in paths)


def _uncovered(region, paths) -> float:
    beads = shapely.union_all([LineString(p.points).buffer(0.5 * (p.width or WIDTH))
                               for p in paths])
    return region.difference(beads).area


def _closest_other_bead(paths) -> float:
    """Least distance between points of two different paths (sampled along each)."""
    from scipy.spatial import cKDTree

    points, owner = [], []
    for k, path in enumerate(paths):
        line = LineString(path.points)
        along = np.linspace(0.0, line.length, max(2, int(line.length * SAMPLES_PER_MM)))
        points.append(shapely.get_coordinates(shapely.line_interpolate_point(line, along)))
        owner.append(np.full(len(along), k))
    points, owner = np.vstack(points), np.concatenate(owner)
    pairs = cKDTree(points).query_pairs(SPACING, output_type="ndarray")
    pairs = pairs[owner[pairs[:, 0]] != owner[pairs[:, 1]]]
    if not len(pairs):
        return SPACING
    return float(np.linalg.norm(points[pairs[:, 0]] - points[pairs[:, 1]], axis=1).min())


def test_a_wall_without_room_for_a_second_loop_gets_gap_fill_instead():
    """A 1.2 mm wall under 0.4 mm beads: the second loop's inset is a strip 0.086 mm wide,
    so the two inner loops lay 0.086 mm apart, overlapping by 75 % (19 % more material than
    the wall holds). Now the external loops only, and one bead along the middle of the gap
    between them, as wide as fills it."""
    wall = _tube(1.2)
    walls = perimeter_walls(wall, WIDTH, 2, SPACING)
    assert len(walls.depths) == 1 and len(walls.depths[0]) == 2
    gap = 1.2 - WIDTH - SPACING                      # between the loops' half-spacing lines
    assert not walls.gaps
    assert sum(piece.area for piece in walls.interior) == pytest.approx(
        gap * box(0.6, 0.6, 39.4, 29.4).length, rel=0.01)
    paths = _fill(wall)
    assert sorted((p.role, p.closed) for p in paths) == [
        ("external_perimeter", True), ("external_perimeter", True), ("perimeter", True)]
    (middle,) = [p for p in paths if p.role == "perimeter"]
    assert middle.width == pytest.approx(gap + WIDTH - SPACING, abs=1e-3)
    assert shapely.hausdorff_distance(LineString(middle.points),
                                      box(0.6, 0.6, 39.4, 29.4).exterior) < AXIS_SLACK


@pytest.mark.parametrize("wall", [0.8, 0.9, 1.0, 1.2, 1.5, 1.6, 1.7, 1.8, 2.0])
def test_walls_are_filled_neither_over_nor_under(wall):
    """Walls of 0.8 to 2 mm (1.6-1.8 mm: loops widened, `island_walls`): the beads cover the
    section but for the outline's corners, no
    two beads lie closer than half a spacing, and they carry 89-100 % of the wall (the
    external loops' outer sides are round: 0.8 mm, two touching loops, is 89 %). A 0.9 mm
    wall left a 0.14 mm strip unfilled, a 1 mm wall got a solid line over its gap (110 %),
    1.2 mm overlapping loops (119 %), a 2 mm wall a sparse line or none inside its loops."""
    region = _tube(wall)
    paths = _fill(region)
    assert _uncovered(region, paths) < CORNER_SHARE * region.area
    assert _closest_other_bead(paths) > 0.5 * SPACING
    assert 0.89 < _laid(paths) / (region.area * HEIGHT) <= 1.0


def test_a_thin_fin_on_a_block_gets_gap_fill_and_no_infill():
    """A 1.2 mm fin on a block: the block gets both loops and infill, the fin its external
    loop and a gap-fill bead along its middle from the block's loops to its end; no infill
    line enters the fin."""
    block, fin = box(0, 0, 10, 10), box(10, 4.4, 30, 5.6)
    region = block.union(fin)
    paths = _fill(region, solid_below_area=0.0)
    assert all(not LineString(p.points).intersects(box(11, 4, 30, 6))
               for p in paths if "infill" in p.role)
    gaps = [p for p in paths if p.role == "perimeter" and p.width is not None]
    (bead,) = gaps
    assert np.allclose(bead.points[:, 1], 5.0, atol=AXIS_SLACK)
    assert bead.points[:, 0].min() < 10.5 and bead.points[:, 0].max() > 29.0
    assert _uncovered(fin, paths) < CORNER_SHARE * fin.area


@pytest.mark.parametrize("wall", [0.9, 1.2, 1.7, 2.0])
def test_the_cost_estimate_lays_what_the_fill_lays(wall):
    """paths/cost.py measures the fill's own loops and gap-fill beads: a wall layer's
    material as estimated is the material the paths carry."""
    region = MultiPolygon([_tube(wall)])
    frame = LayerFrame.for_direction((0.0, 0.0, 1.0))
    layer = Layer(subpart=0, index=5, frame=frame, section_height=1.1, region=region,
                  top_point=np.array([0.0, 0.0, 1.2]), top_normal=np.array([0.0, 0.0, 1.0]),
                  thickness_min=HEIGHT, thickness_max=HEIGHT)
    settings = PathSettings(fill=FillSettings(bead_width=WIDTH))
    cost = layer_cost(layer, None, settings, Motion(acceleration=800.0))
    paths = fill_layer(region, settings.fill, layer.index, height=HEIGHT)
    assert cost.material == pytest.approx(_laid(paths), rel=1e-6)
    assert cost.length == pytest.approx(sum(p.length for p in paths), rel=1e-6)
    assert cost.material <= region.area * HEIGHT


def test_a_wall_leaving_a_band_inside_its_loops_gets_them_widened_instead_of_gap_fill():
    """A 1.7 mm tube wall holds two 0.4 mm loops a side and a 0.23 mm band between them,
    which took one more loop of gap fill on every layer. The four loops are widened by a
    quarter of the band each instead: the same four loops, evenly spaced across the wall,
    and nothing else."""
    wall = 1.7
    band = wall - WIDTH - 3 * SPACING
    walls = island_walls(_tube(wall), WIDTH, 2, SPACING)
    assert walls.width == pytest.approx(WIDTH + band / 4, rel=1e-6)
    assert walls.spacing == pytest.approx(SPACING + band / 4, rel=1e-6)
    assert [len(rings) for rings in walls.depths] == [2, 2] and not walls.interior
    paths = _fill(_tube(wall))
    assert sorted(p.role for p in paths) == ["external_perimeter"] * 2 + ["perimeter"] * 2
    assert all(p.width == pytest.approx(walls.width) for p in paths)
    # Centres at w'/2 and w'/2 + s' from the outside: the last loop's half spacing meets
    # the other side's.
    outer = [p for p in paths if p.role == "external_perimeter"]
    xs = sorted(float(p.points[:, 0].min()) for p in paths)
    assert xs[0] == pytest.approx(walls.width / 2, abs=1e-6)
    assert xs[1] == pytest.approx(walls.width / 2 + walls.spacing, abs=1e-6)
    assert len(outer) == 2


@pytest.mark.parametrize("region", [
    box(0, 0, 10, 10).difference(box(1.7, 1.7, 8.3, 8.3)).union(box(0, 0, 4, 4)),
    box(0, 0, 40, 30).difference(box(1.7, 1.7, 38.0, 28.3)),
], ids=["infill in a corner", "one side thicker"])
def test_loops_are_widened_only_where_they_leave_one_even_band(region):
    """Loops that leave room for infill, or a band uneven enough that widened loops would
    leave a gap, are laid at their own width with gap fill, as before."""
    walls = island_walls(region, WIDTH, 2, SPACING)
    assert walls.width == WIDTH and walls.spacing == SPACING


def test_a_band_wider_than_the_loops_may_grow_keeps_its_gap_fill():
    """Four loops may each grow by MAX_WIDENING of a bead: a 2 mm wall's 0.53 mm band would
    take a third more each, and keeps its gap-fill bead."""
    band = 2.0 - WIDTH - 3 * SPACING
    assert band / 4 > MAX_WIDENING * WIDTH
    walls = island_walls(_tube(2.0), WIDTH, 2, SPACING)
    assert walls.width == WIDTH and walls.interior


@pytest.mark.parametrize("perimeters", [2, 3, 5])
def test_walls_with_room_for_fewer_loops_than_asked_are_widened_the_same(perimeters):
    """A 1.7 mm wall has room for two loops a side whatever the count asked: three or five
    perimeters give the same widened loops as two. A 0.9 mm wall, room for the external
    loops only and a 0.14 mm band (a gap bead 0.19 mm wide, thinner than the layer), gets
    those two widened to 0.47 mm."""
    two = island_walls(_tube(1.7), WIDTH, 2, SPACING)
    more = island_walls(_tube(1.7), WIDTH, perimeters, SPACING)
    assert more.width == pytest.approx(two.width) and more.width > WIDTH
    assert [len(rings) for rings in more.depths] == [2, 2]
    thin = island_walls(_tube(0.9), WIDTH, perimeters, SPACING)
    assert thin.width == pytest.approx(WIDTH + 0.5 * (0.9 - WIDTH - SPACING), rel=1e-6)
    assert [len(rings) for rings in thin.depths] == [2] and not thin.interior
