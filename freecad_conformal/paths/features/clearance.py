"""Every move of a feature program checked against the tool's real envelope.

Obstacles are balls: the part's surface sampled (radius 0) and every cure segment's path
sampled with the radius of what it cured (half the line width or rod diameter), each tagged
with the segment that built it. Every pose the tool passes through (travels, approaches,
retracts, tool changes and cures, sampled every `POSE_STEP` mm along each move, the axis
interpolated) is tested against the obstacles built before that segment: at height h above
the tip along the tool axis the envelope (process/tools.Envelope: cone tip, body cylinder)
has radius r(h); a ball of radius R at height h and distance ρ from the axis is hit when
ρ < r(h) + R.

Material at or below the tip (h ≤ `WORKING_ALLOWANCE`) is what the tool works on (the face it
cures onto, the layer below, the line beside it in the same layer) and is not a collision;
the curvature rule (process/selection.py) is what keeps a tool from being too wide for a
concave face, and it shows here as part samples above the tip plane.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from freecad_conformal.process.tools import Envelope
from freecad_conformal.toolpath import KINDS, Toolpath

#: Poses are sampled this often (mm) along every move: below the narrowest envelope
#: bodies (3 mm), so a contact between two poses is shallower than about 0.02 mm.
POSE_STEP = 0.5
#: Envelope samples along the tool axis (mm); the search radius covers the gap between them.
AXIS_STEP = 1.0
#: Material up to this height above the tip plane (mm) is the working layer (see above).
WORKING_ALLOWANCE = 0.02
#: Overlaps below this (mm) are sampling noise of the ball chains, not contacts.
OVERLAP_TOLERANCE = 1e-3
#: Part surface samples are at most this far apart (mm), fewer on very large parts: a
#: body of radius 1.5 mm can dip 0.75²/(8·1.5) < 0.05 mm between samples unseen.
PART_SPACING = 0.75
MAX_PART_SAMPLES = 400_000


@dataclass(frozen=True)
class Contact:
    segment: int
    kind: str
    point: tuple[float, float, float]
    overlap: float
    obstacle: str        # "part" or "segment N"


def part_samples(shape, spacing: float = PART_SPACING) -> np.ndarray:
    """Points on the surface of a FreeCAD shape, at most about `spacing` apart."""
    area = float(shape.Area)
    spacing = max(spacing, math.sqrt(area / MAX_PART_SAMPLES))
    vertices, triangles = shape.tessellate(spacing / 4.0)
    xyz = np.array([tuple(v) for v in vertices], dtype=float)
    tris = np.array(triangles, dtype=int).reshape(-1, 3)
    out = [xyz]
    if len(tris):
        a, b, c = xyz[tris[:, 0]], xyz[tris[:, 1]], xyz[tris[:, 2]]
        longest = np.max(np.linalg.norm(np.stack([b - a, c - b, a - c]), axis=2), axis=0)
        splits = np.ceil(longest / spacing).astype(int)
        for n in np.unique(splits[splits > 1]):
            rows = np.flatnonzero(splits == n)
            i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
            keep = (i + j) <= n
            s, t = i[keep] / n, j[keep] / n
            pts = (a[rows, None, :] + s[None, :, None] * (b - a)[rows, None, :]
                   + t[None, :, None] * (c - a)[rows, None, :])
            out.append(pts.reshape(-1, 3))
    return np.concatenate(out)


def _resample(points: np.ndarray, step: float) -> tuple[np.ndarray, np.ndarray]:
    """Points along a polyline at most `step` apart, with the fraction along each piece."""
    out, index = [points[:1]], [np.zeros(1)]
    for k, (a, b) in enumerate(zip(points[:-1], points[1:])):
        n = max(int(math.ceil(np.linalg.norm(b - a) / step)), 1)
        t = np.arange(1, n + 1) / n
        out.append(a + np.outer(t, b - a))
        index.append(k + t)
    return np.concatenate(out), np.concatenate(index)


def _poses(points: np.ndarray, axes: np.ndarray, step: float) -> tuple[np.ndarray, np.ndarray]:
    tips, where = _resample(points, step)
    lo = np.clip(np.floor(where).astype(int), 0, len(points) - 1)
    hi = np.clip(lo + 1, 0, len(points) - 1)
    w = (where - lo)[:, None]
    ax = (1 - w) * axes[lo] + w * axes[hi]
    return tips, ax / np.linalg.norm(ax, axis=1)[:, None]


def check_toolpath(tp: Toolpath, envelopes: dict[int, Envelope], cured_width: np.ndarray,
                   part: np.ndarray | None = None, limit: int | None = None) -> list[Contact]:
    """Contacts of every pose of `tp` with the part samples and with earlier cures.

    `envelopes` maps tool numbers to their envelopes; `cured_width` gives per segment the
    width (mm) it cures (0 for travels). Stops after `limit` contacts when given."""
    starts = tp.segment_starts
    cure = KINDS.index("cure")
    centres, radii, order = [np.empty((0, 3))], [np.empty(0)], [np.empty(0, dtype=int)]
    if part is not None and len(part):
        centres.append(part)
        radii.append(np.zeros(len(part)))
        order.append(np.full(len(part), -1))
    for s in range(tp.segment_count):
        if tp.kind[s] == cure and cured_width[s] > 0:
            radius = cured_width[s] / 2.0
            pts, _ = _resample(tp.points[starts[s]:starts[s + 1]], min(radius, POSE_STEP / 2))
            centres.append(pts)
            radii.append(np.full(len(pts), radius))
            order.append(np.full(len(pts), s))
    obstacle_xyz = np.concatenate(centres)
    obstacle_r, obstacle_order = np.concatenate(radii), np.concatenate(order)
    if not len(obstacle_xyz):
        return []
    tree = cKDTree(obstacle_xyz)
    low, high = obstacle_xyz.min(axis=0), obstacle_xyz.max(axis=0)
    found: list[Contact] = []
    for s in range(tp.segment_count):
        env = envelopes[int(tp.tool[s])]
        heights = np.arange(0.0, env.tip_length + env.body_length + AXIS_STEP, AXIS_STEP)
        r_env = np.array([env.radius_at(h) for h in heights])
        reach = float(r_env.max() + obstacle_r.max() + AXIS_STEP)
        a, b = starts[s], starts[s + 1]
        # the move into a segment's first point belongs to it (toolpath.py)
        first = max(a - 1, 0)
        tips, axes = _poses(tp.points[first:b], tp.axes[first:b], POSE_STEP)
        samples = tips[:, None, :] + heights[None, :, None] * axes[:, None, :]
        flat = samples.reshape(-1, 3)
        near = np.all((flat >= low - reach) & (flat <= high + reach), axis=1)
        if not near.any():
            continue
        pose_of = np.repeat(np.arange(len(tips)), len(heights))[near]
        pairs = cKDTree(flat[near]).sparse_distance_matrix(tree, reach, output_type="ndarray")
        if not len(pairs):
            continue
        pose, obstacle = pose_of[pairs["i"]], pairs["j"]
        keep = obstacle_order[obstacle] < s
        pose, obstacle = pose[keep], obstacle[keep]
        rel = obstacle_xyz[obstacle] - tips[pose]
        h = np.einsum("ij,ij->i", rel, axes[pose])
        rho = np.linalg.norm(rel - h[:, None] * axes[pose], axis=1)
        inside = h > WORKING_ALLOWANCE
        overlap = np.where(inside, np.interp(h, heights, r_env, right=0.0)
                           + obstacle_r[obstacle] - rho, -np.inf)
        if not len(overlap) or overlap.max() <= OVERLAP_TOLERANCE:
            continue
        k = int(np.argmax(overlap))
        o = int(obstacle_order[obstacle[k]])
        found.append(Contact(s, KINDS[tp.kind[s]], tuple(float(v) for v in tips[pose[k]]),
                             float(overlap[k]), "part" if o < 0 else f"segment {o}"))
        if limit is not None and len(found) >= limit:
            break
    return found

