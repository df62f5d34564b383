"""Gap-fill beads in fewer pieces and laid with their island's loops: pieces whose ends meet
are one bead, and the beads follow the loops nearest first, so the head does not cross the
part between walls (a hollow box's travel had doubled)."""
from __future__ import annotations

import numpy as np
import pytest
from shapely import affinity
from shapely.geometry import box

from freecad_conformal.paths.bead import bead_area, bead_spacing
from freecad_conformal.paths.fill2d import (FillSettings, IslandFill, Path2D, fill_layer, gap_fill,
                                            ordered_fill, perimeter_walls)
from freecad_conformal.paths.thin_walls import (JOIN_REACH_SHARE, JOIN_WIDTH_SHARE, gap_beads,
                                                 joined_beads)

WIDTH, HEIGHT = 0.4, 0.2
SPACING = bead_spacing(WIDTH, HEIGHT)
WALL = 1.2


def _ribbed_box(rib: float = WALL):
    """A 40 x 30 mm box's wall section, 1.2 mm walls, a rib across its middle."""
    outer = box(0, 0, 40, 30)
    return outer.difference(box(WALL, WALL, 20 - rib / 2, 30 - WALL)).difference(
        box(20 + rib / 2, WALL, 40 - WALL, 30 - WALL))


def _length(points: np.ndarray) -> float:
    return float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum())


def _bead(*points, width=0.45):
    return np.array(points, dtype=float), width, False


def test_pieces_meeting_at_a_junction_join_straightest_first():
    """A T junction (a rib off a wall): of the three pieces ending there, the wall's two
    continue straight through it and are joined; the rib's piece stays a bead of its own
    (its end then meets no bead's end). Nothing is lost or added."""
    left, right = _bead((0, 0), (5, 0)), _bead((5, 0), (10, 0))
    rib = _bead((5, 0), (5, 6))
    joined = joined_beads([rib, left, right], WIDTH)
    assert len(joined) == 2
    (wall,) = [points for points, _, _ in joined if len(points) == 3]
    assert {tuple(wall[0]), tuple(wall[-1])} == {(0.0, 0.0), (10.0, 0.0)}
    assert sum(_length(points) for points, _, _ in joined) == pytest.approx(16.0)
    assert all(not closed and width == 0.45 for _, width, closed in joined)


def test_pieces_apart_or_of_other_widths_stay_apart():
    """Ends further apart than `JOIN_REACH_SHARE` of a bead, or widths differing by more
    than `JOIN_WIDTH_SHARE` of one, are two beads; ends just apart join across the gap."""
    a = _bead((0, 0), (5, 0))
    far = _bead((5 + 1.1 * JOIN_REACH_SHARE * WIDTH, 0), (10, 0))
    assert len(joined_beads([a, far], WIDTH)) == 2
    other = _bead((5, 0), (10, 0), width=0.45 + 1.1 * JOIN_WIDTH_SHARE * WIDTH)
    assert len(joined_beads([a, other], WIDTH)) == 2
    near = _bead((5 + 0.5 * JOIN_REACH_SHARE * WIDTH, 0), (10, 0))
    ((points, _, _),) = joined_beads([a, near], WIDTH)
    assert _length(points) == pytest.approx(10.0)


def test_joined_width_is_the_length_weighted_mean():
    """Widths that agree within `JOIN_WIDTH_SHARE` become their length-weighted mean, so a
    bead wider than the layer is high carries the pieces' material."""
    a = _bead((0, 0), (3, 0), width=0.44)
    b = _bead((3, 0), (4, 0), width=0.45)
    ((points, width, _),) = joined_beads([a, b], WIDTH)
    assert width == pytest.approx((3 * 0.44 + 1 * 0.45) / 4)
    laid = _length(points) * bead_area(width, HEIGHT)
    assert laid == pytest.approx(3 * bead_area(0.44, HEIGHT) + bead_area(0.45, HEIGHT))


def test_a_ribbed_box_gets_one_gap_bead_not_three():
    """The gap inside a 1.2 mm box wall with a 1.2 mm rib: its axis is three pieces meeting
    at the rib's two junctions, each laid apart (three starts and stops). Joined, one
    bead of the same length and material."""
    walls = perimeter_walls(_ribbed_box(), WIDTH, 2, SPACING)
    pieces = gap_beads(walls.gaps + walls.interior, WIDTH, SPACING)
    assert len(pieces) == 3
    paths, _ = gap_fill(walls, FillSettings(bead_width=WIDTH), SPACING)
    (bead,) = paths
    assert bead.length == pytest.approx(sum(_length(p) for p, _, _ in pieces), rel=1e-9)
    assert bead.length * bead_area(bead.width, HEIGHT) == pytest.approx(
        sum(_length(p) * bead_area(w, HEIGHT) for p, w, _ in pieces), rel=1e-9)


def test_a_narrower_rib_keeps_its_own_bead():
    """A 1 mm rib in a box of 1.2 mm walls: its gap is narrower, its bead too; the wall's
    two pieces join round the box and the rib's stays apart, at its own width."""
    walls = perimeter_walls(_ribbed_box(rib=1.0), WIDTH, 2, SPACING)
    paths, _ = gap_fill(walls, FillSettings(bead_width=WIDTH), SPACING)
    assert len(paths) == 2
    rib, wall = sorted(paths, key=lambda p: p.length)
    assert rib.width < wall.width - JOIN_WIDTH_SHARE * WIDTH
    assert np.allclose(rib.points[:, 0], 20.0, atol=0.05)


def _travel(paths, start=(0.0, 0.0)) -> float:
    here, total = np.asarray(start, dtype=float), 0.0
    for path in paths:
        total += float(np.linalg.norm(path.points[0] - here))
        here = path.points[-1]
    return total


def _is_gap(path) -> bool:
    return path.role == "perimeter" and path.width is not None


def test_gap_beads_come_right_after_their_islands_loops():
    """A block with a 1.2 mm fin (its gap bead runs from the block's loops to the fin's
    end) and a ribbed box beside it: in each island the gap beads follow the loops,
    before any infill line; they used to be laid in the infill's order."""
    block = box(0, 0, 10, 10).union(box(10, 4.4, 30, 5.6))
    region = block.union(affinity.translate(_ribbed_box(), 40.0))
    settings = FillSettings(bead_width=WIDTH, perimeters=2, density=0.2, solid_below_area=0.0)
    paths = fill_layer(region, settings, height=HEIGHT)
    kinds = ["gap" if _is_gap(p) else ("loop" if p.closed and "perimeter" in p.role
                                        else "infill") for p in paths]
    assert kinds.count("gap") == 2 and "infill" in kinds
    # per island: loops, gap beads, infill; the islands one after the other
    runs = [k for i, k in enumerate(kinds) if i == 0 or k != kinds[i - 1]]
    assert runs in (["loop", "gap", "infill", "loop", "gap"], ["loop", "gap", "loop", "gap", "infill"])


def test_a_closed_gap_bead_is_entered_where_the_loops_end():
    """An 80 x 50 mm tube of 1.2 mm walls: its gap bead is one closed loop. It started at
    its first vertex, a corner across the part from where the loops end (the layer's
    travel 99 mm); now at its vertex nearest the nozzle, a bead's width away."""
    tube = box(0, 0, 80, 50).difference(box(WALL, WALL, 80 - WALL, 50 - WALL))
    paths = fill_layer(tube, FillSettings(bead_width=WIDTH), height=HEIGHT,
                       position=np.zeros(2))
    (k,) = [i for i, p in enumerate(paths) if _is_gap(p)]
    assert k == len(paths) - 1 and paths[k].closed
    assert np.linalg.norm(paths[k].points[0] - paths[k - 1].points[-1]) < 2 * WIDTH
    assert _travel(paths) < 52.0


def test_open_beads_are_laid_nearest_first_from_their_nearer_end():
    """After the loop (which ends at its seam, (0, 10)): the nearer bead first, laid from
    its far end when that end is the nearer one, then the other from where that one
    ended."""
    square = np.array([(0, 10), (10, 10), (10, 0), (0, 0), (0, 10)], dtype=float)
    near = Path2D(np.array([(4.0, 9.0), (1.0, 9.0)]), "perimeter", False, 0.45)
    far = Path2D(np.array([(9.0, 1.0), (4.0, 1.0)]), "perimeter", False, 0.45)
    island = IslandFill(box(0, 0, 10, 10), [[square]], [], [far, near])
    paths = ordered_fill([island], FillSettings(bead_width=WIDTH), np.array([0.0, 10.0]))
    assert [p.closed for p in paths] == [True, False, False]
    assert np.allclose(paths[1].points, near.points[::-1])      # reversed: (1, 9) was nearer
    assert np.allclose(paths[2].points, far.points[::-1])       # from (4, 1), below (4, 9)
