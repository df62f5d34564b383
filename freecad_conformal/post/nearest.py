"""Nearest pose on a polyline of tool poses, for many query poses at once (numpy only).

The polyline is cut into pieces no longer than a grid cell and each piece is filed under
the cell of its midpoint; a query looks at its own cell and the 26 around it (as 9 columns of 3). Any piece
with a point within `radius` of the query is then among the candidates (cell >= 2 radius,
piece <= cell), so within `radius` the answer is exact; queries with no candidate that
close are asked again with twice the radius, until every query has an answer.

The match weighs the tool axis too (cost = distance + POSE_LEVER × angle), so where the
tip stands still while the axis turns, the axis decides which part of the path it is on.
"""
from __future__ import annotations

import numpy as np

from freecad_conformal.post.linearize import ZERO_CHORD, slerp
from freecad_conformal.tolerances import DIVISION_GUARD, RECIPROCAL_GUARD

#: Matching weighs the axis angle as tip motion at this lever (mm per rad, about a tool's
#: length), so where the tip stands still the axis decides.
POSE_LEVER = 50.0

#: First search radius (mm): a few times the usual tolerance, small enough that a cell
#: holds few pieces of a dense path.
FIRST_RADIUS = 0.02

#: Points whose guessed bound is at least this share of the largest bound are searched in
#: full first (nearest_where_it_matters): few enough to be cheap, and the exact maximum is
#: nearly always among them, so no second round is needed.
CLOSE_TO_WORST = 0.8

#: Candidates handled at once (memory: about 200 bytes each).
CHUNK = 2_000_000

#: The 3 × 3 columns of cells around a query; each column's three cells along Z are
#: consecutive keys, so one pair of binary searches finds all three.
_COLUMNS = np.array([[dx, dy, 0] for dx in (-1, 0, 1) for dy in (-1, 0, 1)])


def _arc_parameter(a: np.ndarray, b: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Slerp parameter of the point of the arc a -> b nearest to the unit vector q."""
    across = b - np.einsum("ij,ij->i", a, b)[:, None] * a
    width = np.linalg.norm(across, axis=1)
    total = np.arctan2(width, np.einsum("ij,ij->i", a, b))
    phi = np.arctan2(np.einsum("ij,ij->i", q, across) / np.maximum(width, DIVISION_GUARD),
                     np.einsum("ij,ij->i", q, a))
    return np.clip(phi / np.maximum(total, DIVISION_GUARD), 0.0, 1.0)


def _pieces(path: np.ndarray, cell: float) -> tuple[np.ndarray, np.ndarray]:
    """Midpoints of pieces no longer than `cell`, and the polyline move of each."""
    chord = np.diff(path, axis=0)
    parts = np.maximum(np.ceil(np.linalg.norm(chord, axis=1) / cell), 1).astype(np.int64)
    move = np.repeat(np.arange(len(chord)), parts)
    first = np.cumsum(parts) - parts
    s = (np.arange(len(move)) - first[move] + 0.5) / parts[move]
    return path[move] + chord[move] * s[:, None], move


def _keys(cells: np.ndarray) -> np.ndarray:
    c = cells.astype(np.int64) + (1 << 20)
    return (c[:, 0] << 42) | (c[:, 1] << 21) | c[:, 2]


def _moves(path: np.ndarray, path_axes: np.ndarray) -> np.ndarray:
    """Per polyline move, packed for one gather: start, chord, 1/length², start axis, axis
    turn, 1/turn², and whether it is a pure reorientation."""
    chord = np.diff(path, axis=0)
    turn = np.diff(path_axes, axis=0)
    length2 = np.einsum("ij,ij->i", chord, chord)
    turn2 = np.einsum("ij,ij->i", turn, turn)
    packed = np.column_stack([path[:-1], chord, 1.0 / np.maximum(length2, RECIPROCAL_GUARD), path_axes[:-1],
                              turn, 1.0 / np.maximum(turn2, RECIPROCAL_GUARD), length2 <= ZERO_CHORD ** 2])
    return packed


def _screen(poses: np.ndarray, moves: np.ndarray) -> np.ndarray:
    """A cheap matching cost for many (pose, move) pairs, rows of `_moves` and (n, 6)
    poses: tip distance plus the lever times the chord between the pose's axis and the
    linearly blended design axis."""
    offset = poses[:, :3] - moves[:, 0:3]
    chord = moves[:, 3:6]
    t = np.clip(np.einsum("ij,ij->i", offset, chord) * moves[:, 6], 0.0, 1.0)
    axis_offset = poses[:, 3:] - moves[:, 7:10]
    turn = moves[:, 10:13]
    t_axis = np.clip(np.einsum("ij,ij->i", axis_offset, turn) * moves[:, 13], 0.0, 1.0)
    offset -= t[:, None] * chord
    axis_offset -= np.where(moves[:, 14] > 0, t_axis, t)[:, None] * turn
    return (np.sqrt(np.einsum("ij,ij->i", offset, offset))
            + POSE_LEVER * np.sqrt(np.einsum("ij,ij->i", axis_offset, axis_offset)))


def _evaluate(points, axes, path, path_axes, query, move):
    """Distance and axis angle (slerp, as the toolpath defines it) from query poses to moves."""
    a, b = path[move], path[move + 1]
    chord = b - a
    length2 = np.einsum("ij,ij->i", chord, chord)
    p = points[query]
    t = np.clip(np.einsum("ij,ij->i", p - a, chord) / np.maximum(length2, DIVISION_GUARD), 0.0, 1.0)
    distance = np.linalg.norm(a + t[:, None] * chord - p, axis=1)
    axis_a, axis_b = path_axes[move], path_axes[move + 1]
    # a pure reorientation (the tip does not move): the nearest axis on its arc
    still = np.flatnonzero(length2 <= ZERO_CHORD ** 2)
    if len(still):
        t[still] = _arc_parameter(axis_a[still], axis_b[still], axes[query[still]])
    designed = slerp(axis_a, axis_b, t)
    angle = np.arccos(np.clip(np.einsum("ij,ij->i", designed, axes[query]), -1.0, 1.0))
    return distance, angle


def nearest_poses(points: np.ndarray, axes: np.ndarray, path: np.ndarray,
                  path_axes: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per query pose: distance (mm) and axis angle (rad) to the best-matching path pose,
    and the path move (k: from path point k to k + 1) it lies on."""
    n = len(points)
    if len(path) == 1:
        distance = np.linalg.norm(points - path[0], axis=1)
        return (distance, np.arccos(np.clip(axes @ path_axes[0], -1.0, 1.0)),
                np.zeros(n, dtype=np.int64))
    distance, angle, matched = np.full(n, np.inf), np.zeros(n), np.zeros(n, dtype=np.int64)
    extent = float(np.ptp(np.vstack([points, path]), axis=0).max()) + 1.0
    todo, radius = np.arange(n), FIRST_RADIUS
    packed = _moves(path, path_axes)
    while len(todo):
        cell = max(2.0 * radius, extent / 2 ** 19)     # cell indices fit the 21-bit keys
        mids, move = _pieces(path, cell)
        keys = _keys(np.floor(mids / cell))
        order = np.argsort(keys, kind="stable")
        keys, move = keys[order], move[order]
        home = np.floor(points[todo] / cell).astype(np.int64)
        for chunk in np.array_split(todo, max(1, len(todo) * 27 // CHUNK + 1)):
            _match(chunk, home[np.searchsorted(todo, chunk)], keys, move, packed, points, axes,
                   path, path_axes, (distance, angle, matched))
        done = distance[todo] <= radius
        if radius > extent:          # every piece has been a candidate
            break
        todo, radius = todo[~done], radius * 2.0
    return distance, angle, matched


def near_guess(points: np.ndarray, axes: np.ndarray, path: np.ndarray, path_axes: np.ndarray,
               guess: np.ndarray, spread: int = 1) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Like `nearest_poses`, but looking only at the moves within `spread` of `guess`:
    the result is a pose on the path, so its distance is an upper bound of the nearest."""
    moves = np.clip(guess[:, None] + np.arange(-spread, spread), 0, len(path) - 2)   # (n, k)
    start, start_axis = path[moves], path_axes[moves]                                 # (n, k, 3)
    chord, turn = path[moves + 1] - start, path_axes[moves + 1] - start_axis
    length2 = np.einsum("nkj,nkj->nk", chord, chord)
    offset = points[:, None, :] - start
    t = np.clip(np.einsum("nkj,nkj->nk", offset, chord) / np.maximum(length2, DIVISION_GUARD), 0.0, 1.0)
    axis_offset = axes[:, None, :] - start_axis
    turn2 = np.einsum("nkj,nkj->nk", turn, turn)
    t_axis = np.clip(np.einsum("nkj,nkj->nk", axis_offset, turn) / np.maximum(turn2, DIVISION_GUARD),
                     0.0, 1.0)
    offset -= t[..., None] * chord
    axis_offset -= np.where(length2 <= ZERO_CHORD ** 2, t_axis, t)[..., None] * turn
    cost = (np.sqrt(np.einsum("nkj,nkj->nk", offset, offset))      # as _screen, per move
            + POSE_LEVER * np.sqrt(np.einsum("nkj,nkj->nk", axis_offset, axis_offset)))
    best = moves[np.arange(len(points)), np.argmin(cost, axis=1)]
    distance, angle = _evaluate(points, axes, path, path_axes, np.arange(len(points)), best)
    return distance, angle, best


def arc_length_guess(points: np.ndarray, path: np.ndarray) -> np.ndarray:
    """Per point of an ordered polyline that follows `path` (a replay of it), the path move
    at the same fraction of the length along both: a guess for `near_guess`."""
    def along(line: np.ndarray) -> np.ndarray:
        return np.concatenate(([0.0], np.cumsum(np.linalg.norm(np.diff(line, axis=0), axis=1))))

    on_path, on_points = along(path), along(points)
    scale = on_path[-1] / on_points[-1] if on_points[-1] > 0 else 0.0
    return np.clip(np.searchsorted(on_path, on_points * scale) - 1, 0, len(path) - 2)


def nearest_where_it_matters(points: np.ndarray, axes: np.ndarray, path: np.ndarray,
                             path_axes: np.ndarray, guess: np.ndarray,
                             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """`nearest_poses` for the points that decide the largest distance and angle, upper
    bounds (`near_guess`) for the rest: the maxima are those of `nearest_poses`.

    A guessed match bounds a point's distance from above, so a point whose bound is below
    the largest exact distance found cannot raise it; only points whose bounds reach
    CLOSE_TO_WORST of the largest bound are searched in full, then any still above the
    exact maximum, until none is.
    """
    distance, angle, matched = near_guess(points, axes, path, path_axes, guess)
    exact = np.zeros(len(points), dtype=bool)
    ask = (distance >= CLOSE_TO_WORST * distance.max()) | (angle >= CLOSE_TO_WORST * angle.max())
    while ask.any():
        rows = np.flatnonzero(ask)
        distance[rows], angle[rows], matched[rows] = nearest_poses(points[rows], axes[rows], path,
                                                                   path_axes)
        exact[rows] = True
        worst_distance, worst_angle = distance[exact].max(), angle[exact].max()
        ask = ~exact & ((distance > worst_distance) | (angle > worst_angle))
    return distance, angle, matched


def _match(queries, home, keys, move, packed, points, axes, path, path_axes, out) -> None:
    distance, angle, matched = out
    around = _keys((home[:, None, :] + _COLUMNS[None]).reshape(-1, 3))
    low = np.searchsorted(keys, around - 1, side="left")
    high = np.searchsorted(keys, around + 1, side="right")
    counts = high - low
    per_query = counts.reshape(-1, len(_COLUMNS)).sum(axis=1)
    if per_query.sum() == 0:
        return
    start = np.repeat(low - (np.cumsum(counts) - counts), counts)
    candidate = move[start + np.arange(len(start))]
    query = np.repeat(queries, per_query)              # candidates are grouped by query
    poses = np.repeat(np.column_stack([points[queries], axes[queries]]), per_query, axis=0)
    cost = _screen(poses, packed[candidate])
    found = per_query > 0
    group = (np.cumsum(per_query) - per_query)[found]
    lowest = np.minimum.reduceat(cost, group)
    index = np.where(cost == np.repeat(lowest, per_query[found]), np.arange(len(cost)), len(cost))
    best = np.minimum.reduceat(index, group)
    d, a = _evaluate(points, axes, path, path_axes, query[best], candidate[best])
    target = query[best]
    better = d + POSE_LEVER * a < distance[target] + POSE_LEVER * angle[target]
    distance[target[better]] = d[better]
    angle[target[better]] = a[better]
    matched[target[better]] = candidate[best][better]
