"""Scan lines across a 2-D area: the pieces they leave inside it, and the directions
fills are laid in (the infill's candidates, a bridge's span and its anchors).

Everything here is numpy over the area's boundary edges; `paths.fill2d` lays the lines.
"""
from __future__ import annotations

import math

import numpy as np
import shapely
from shapely.geometry import Polygon


#: Angles tried for the fewest-turns infill direction (every 15° over a half turn).
CANDIDATE_ANGLES = tuple(math.radians(a) for a in range(0, 180, 15))


def polygons_of(geometry) -> list[Polygon]:
    """The non-empty polygons of any shapely geometry (none of its lines or points)."""
    if geometry.is_empty:
        return []
    if geometry.geom_type == "Polygon":
        return [geometry]
    return [g for g in getattr(geometry, "geoms", []) if g.geom_type == "Polygon" and not g.is_empty]


#: Scan-line pieces shorter than this (mm) are dropped: a line grazing a vertex leaves a
#: piece of no length, which no bead can lay.
MIN_PIECE = 1e-6


def boundary_edges(area) -> tuple[np.ndarray, np.ndarray] | None:
    """Start and end points (N, 2) of every edge of the area's rings; None when empty."""
    rings = [np.asarray(ring.coords) for poly in polygons_of(area)
             for ring in (poly.exterior, *poly.interiors)]
    if not rings:
        return None
    return (np.concatenate([ring[:-1] for ring in rings]),
            np.concatenate([ring[1:] for ring in rings]))


def scan_pieces(area, spacing: float, angle: float,
                phase: float = 0.5) -> tuple[np.ndarray, float]:
    """The pieces scan lines leave inside `area` (rotated frame, lines along x) as an (N, 3)
    array of (row, x0, x1), unsorted, and the first row's grid offset. Lines sit on a global
    grid, at (k + `phase`) spacings, so sparse lines stack from layer to layer.

    The crossings of every boundary edge with every grid line, in numpy, paired along each
    line by the even-odd rule (an edge spans the lines at low <= y < high, so a vertex on a
    line counts once). GEOS's polygon ∩ lines cost 2.3 s on sliced_cylinder where this
    takes 0.3, and on a ring that turning made self-intersecting it returned the pieces
    outside the area instead."""
    edges = boundary_edges(area)
    if edges is None:
        return np.empty((0, 3)), 0.5
    cos, sin = math.cos(angle), math.sin(angle)
    turn = np.array([[cos, -sin], [sin, cos]])       # row vectors times this: rotate by -angle
    starts, ends = edges[0] @ turn, edges[1] @ turn
    miny = float(min(starts[:, 1].min(), ends[:, 1].min()))
    maxy = float(max(starts[:, 1].max(), ends[:, 1].max()))
    first = math.floor(miny / spacing - phase) + phase
    low, high = np.minimum(starts[:, 1], ends[:, 1]), np.maximum(starts[:, 1], ends[:, 1])
    row_from = np.ceil(low / spacing - first).astype(np.int64)
    counts = np.maximum(np.ceil(high / spacing - first).astype(np.int64) - row_from, 0)
    total = int(counts.sum())
    if total == 0:
        return np.empty((0, 3)), first
    edge = np.repeat(np.arange(len(starts)), counts)
    rows = row_from[edge] + np.arange(total) - np.repeat(np.cumsum(counts) - counts, counts)
    y = (first + rows) * spacing
    a, b = starts[edge], ends[edge]
    x = a[:, 0] + (y - a[:, 1]) * (b[:, 0] - a[:, 0]) / (b[:, 1] - a[:, 1])
    inside = (y > miny) & (y < maxy)
    rows, x = rows[inside], x[inside]
    order = np.lexsort((x, rows))
    rows, x = rows[order], x[order]
    # Each line crosses closed rings an even number of times; a row that does not (a
    # ring left open by rounding) cannot be paired and is left out.
    _, crossings = np.unique(rows, return_counts=True)
    if np.any(crossings % 2):
        keep = np.repeat(crossings % 2 == 0, crossings)
        rows, x = rows[keep], x[keep]
    pieces = np.column_stack((rows[0::2].astype(float), x[0::2], x[1::2]))
    return pieces[pieces[:, 2] - pieces[:, 1] >= MIN_PIECE], first


def span_angle(area, spacing: float, candidates=CANDIDATE_ANGLES) -> float:
    """The candidate direction whose lines across `area` are shortest at their longest: a
    bridge over nothing is laid across its shortest span, each line reaching from one
    side's wall to the other (a sealed slot's ceiling: 8 mm lines, where the fewest-turns
    direction ran 30 mm ones lengthwise over the void). Ties go to the first candidate
    (a square's or a disc's ceiling: the same rows as before on even layers)."""
    return _shortest_span([(candidate, scan_pieces(area, spacing, candidate)[0])
                           for candidate in candidates])


def _shortest_span(scanned: list[tuple[float, np.ndarray]]) -> float:
    """The angle among (angle, its scan pieces) whose longest piece is shortest; ties (to
    `MIN_PIECE`) go to the first."""
    best, angle = math.inf, scanned[0][0]
    for candidate, pieces in scanned:
        longest = float((pieces[:, 2] - pieces[:, 1]).max()) if len(pieces) else 0.0
        if longest < best - MIN_PIECE:
            best, angle = longest, candidate
    return angle


#: A bridge direction anchoring this share of its rows less than the best one's anchors
#: about as well: among those the shortest span is taken (a sealed slot anchors every row
#: in every direction, and its rows differ by the grid's rounding).
ANCHOR_SLACK = 0.05


def anchored_rows(area, spacing: float, angle: float, anchors,
                  reach: float) -> tuple[np.ndarray, float, np.ndarray]:
    """`scan_pieces` of `area` along `angle`, and per piece whether both its ends lie
    within `reach` of `anchors` (what carries a bridge's ends: the layer below)."""
    rows, first = scan_pieces(area, spacing, angle)
    if not len(rows) or anchors is None or anchors.is_empty:
        return rows, first, np.zeros(len(rows), dtype=bool)
    y = (first + rows[:, 0]) * spacing
    ends = np.vstack((np.column_stack((rows[:, 1], y)), np.column_stack((rows[:, 2], y))))
    rests = shapely.distance(anchors, shapely.points(ends @ _unturn(angle))) <= reach
    return rows, first, rests[:len(rows)] & rests[len(rows):]


def _unturn(angle: float) -> np.ndarray:
    """Row vectors in the scan frame times this: back in the area's frame (by +angle)."""
    cos, sin = math.cos(angle), math.sin(angle)
    return np.array([[cos, sin], [-sin, cos]])


def bridge_angle(area, spacing: float, anchors, reach: float) -> float:
    """The direction a bridge over nothing is laid in: the candidate whose rows rest on
    `anchors` at both ends (within `reach`) over the largest share of their length, as
    PrusaSlicer's bridge detector looks for anchors; among those within `ANCHOR_SLACK` of
    it, across the shortest span (`span_angle`). A beam between two pillars is laid from
    one to the other, though it is narrower across; a cantilever, anchored nowhere, and
    a sealed slot's ceiling, anchored everywhere, across their shortest span."""
    scanned, shares = [], []
    for candidate in CANDIDATE_ANGLES:
        rows, _, anchored = anchored_rows(area, spacing, candidate, anchors, reach)
        lengths = rows[:, 2] - rows[:, 1] if len(rows) else np.zeros(0)
        total = float(lengths.sum())
        scanned.append((candidate, rows))
        shares.append(float(lengths[anchored].sum()) / total if total > 0 else 0.0)
    best = max(shares)
    # The same rows decide the span: scanning the close candidates again cost as much.
    return _shortest_span([found for found, share in zip(scanned, shares)
                           if share >= best - ANCHOR_SLACK])


def anchored_cover(area, spacing: float, angle: float, anchors, reach: float):
    """The part of `area` its anchored rows along `angle` cover (each row a spacing wide)."""
    rows, first, anchored = anchored_rows(area, spacing, angle, anchors, reach)
    if not anchored.any():
        return Polygon()
    x0, x1 = rows[anchored, 1], rows[anchored, 2]
    y = (first + rows[anchored, 0]) * spacing
    low, high = y - 0.5 * spacing, y + 0.5 * spacing
    corners = np.stack((np.column_stack((x0, low)), np.column_stack((x1, low)),
                        np.column_stack((x1, high)), np.column_stack((x0, high))), axis=1)
    return shapely.intersection(shapely.union_all(shapely.polygons(corners @ _unturn(angle))),
                                area)
