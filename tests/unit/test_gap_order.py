"""Gap-fill beads in fewer pieces and laid with their island's loops: pieces whose ends meet
are one bead, and the beads follow the loops nearest first, so the head does not cross the
part between walls (a hollow box's travel had doubled)."""
from __future__ import annotations

import numpy as np
import pytest
from shapely.geometry import box

from freecad_conformal.paths.bead import bead_area, bead_spacing
from freecad_conformal.paths.fill2d import FillSettings, gap_fill, perimeter_walls
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
