"""Every move of a feature program checked against the tool's real envelope.

Obstacles are points on surfaces: the part's surface sampled, and the surface of every cured
segment (a tube round its path, `width` across and `thickness` along the tool axis, flat at
its ends), each tagged with the segment that built it. Every pose the tool passes through
(travels, approaches, retracts, tool changes and cures, sampled every `POSE_STEP` mm along
each move, the axis interpolated) is tested against the obstacles built before that segment:
at height h above the tip along the tool axis the envelope (process/tools.Envelope: cone
tip, body cylinder) has radius r(h); a surface point at height h > 0 and distance ρ from the
axis is inside the envelope when ρ < r(h).

What a move works on is not a collision: below the tip plane nothing counts (the face a cure
stands on, the layer below); a cure also stands in its own layer (material less than half
its thickness above the tip plane, the line beside it); an approach or retract does so too
within that half thickness of the cure it lands on or leaves. The curvature rule
(process/selection.py) keeps a tool from being too wide for a concave face; here it shows
as part samples above the tip plane.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from freecad_conformal.process.tools import Envelope
from freecad_conformal.toolpath import KINDS, Toolpath
from freecad_conformal.tolerances import DIVISION_GUARD, ROUNDING_SLACK

#: Poses are sampled this often (mm) along every move: below the narrowest envelope
#: bodies (3 mm), so a contact between two poses is shallower than about 0.02 mm.
POSE_STEP = 0.5
#: Envelope samples along the tool axis (mm); the search radius covers the gap between them.
AXIS_STEP = 1.0
#: Material up to this height above the tip plane (mm) is the working layer (see above).
WORKING_ALLOWANCE = 0.02
#: Overlaps below this (mm) are sampling noise of the ball chains, not contacts.
OVERLAP_TOLERANCE = 1e-3
#: A move whose component across the tool axis is shorter than this (mm) runs along it.
ALONG_AXIS = 1e-6
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


#: Points round a cured tube's section: chords of a 1.2 mm rod's section are 0.31 mm, and
#: a 1.5 mm envelope radius dips 0.31²/(8·1.5) < 0.01 mm between two of them.
SECTION_POINTS = 12


def cured_surface(points: np.ndarray, axes: np.ndarray, width: float,
                  thickness: float) -> np.ndarray:
    """Points on the surface of the material one cure leaves: an elliptic tube round the
    path (`width` across, `thickness` along the tool axis), flat discs at both ends."""
    step = max(min(width, thickness) / 2.0, 0.02)
    centres, where = _resample(points, min(step, POSE_STEP / 2))
    if len(points) < 2:
        return centres
    lo = np.clip(np.floor(where).astype(int), 0, len(points) - 2)
    tangent = points[lo + 1] - points[lo]
    tangent /= np.maximum(np.linalg.norm(tangent, axis=1), DIVISION_GUARD)[:, None]
    ax = axes[np.clip(lo, 0, len(axes) - 1)]
    vertical = ax - np.einsum("ij,ij->i", ax, tangent)[:, None] * tangent
    along = np.linalg.norm(vertical, axis=1) < ALONG_AXIS          # rods: the path is the axis
    seed = np.where(np.abs(tangent[:, :1]) < 0.9, np.array([[1.0, 0, 0]]), np.array([[0, 1.0, 0]]))
    vertical[along] = np.cross(tangent[along], seed[along])
    vertical /= np.linalg.norm(vertical, axis=1)[:, None]
    lateral = np.cross(tangent, vertical)
    half_w = width / 2.0
    half_t = np.where(along, half_w, thickness / 2.0)[:, None]
    phi = np.linspace(0.0, 2 * math.pi, SECTION_POINTS, endpoint=False)
    ring = (centres[:, None, :] + half_w * np.cos(phi)[None, :, None] * lateral[:, None, :]
            + (half_t * np.sin(phi)[None, :])[:, :, None] * vertical[:, None, :])
    out = [ring.reshape(-1, 3), centres]
    for end in (0, -1):                      # flat end discs
        for fraction in (0.5,):
            out.append(centres[end] + fraction * (ring[end] - centres[end]))
    return np.concatenate(out)


def check_toolpath(tp: Toolpath, envelopes: dict[int, Envelope], cured_width: np.ndarray,
                   part: np.ndarray | None = None, limit: int | None = None,
                   cured_thickness: np.ndarray | None = None) -> list[Contact]:
    """Contacts of every pose of `tp` with the part samples and with earlier cures.

    `envelopes` maps tool numbers to their envelopes; `cured_width` and `cured_thickness`
    give per segment the width and thickness (mm) it cures (0 for travels; the thickness
    defaults to the width). Stops after `limit` contacts when given."""
    starts = tp.segment_starts
    cure = KINDS.index("cure")
    thickness = cured_width if cured_thickness is None else cured_thickness
    centres, order = [np.empty((0, 3))], [np.empty(0, dtype=int)]
    if part is not None and len(part):
        centres.append(part)
        order.append(np.full(len(part), -1))
    for s in range(tp.segment_count):
        if tp.kind[s] == cure and cured_width[s] > 0:
            pts = cured_surface(tp.points[starts[s]:starts[s + 1]],
                                tp.axes[starts[s]:starts[s + 1]], cured_width[s], thickness[s])
            centres.append(pts)
            order.append(np.full(len(pts), s))
    obstacle_xyz, obstacle_order = np.concatenate(centres), np.concatenate(order)
    if not len(obstacle_xyz):
        return []
    tree = cKDTree(obstacle_xyz)
    low, high = obstacle_xyz.min(axis=0), obstacle_xyz.max(axis=0)
    found: list[Contact] = []
    for s in range(tp.segment_count):
        env = envelopes[int(tp.tool[s])]
        heights = np.arange(0.0, env.tip_length + env.body_length + AXIS_STEP, AXIS_STEP)
        r_env = np.array([env.radius_at(h) for h in heights])
        reach = float(r_env.max() + AXIS_STEP)
        a, b = starts[s], starts[s + 1]
        # the move into a segment's first point belongs to it (toolpath.py)
        first = max(a - 1, 0)
        tips, axes = _poses(tp.points[first:b], tp.axes[first:b], POSE_STEP)
        allowance = _working_layer(tp, s, tips, cured_width if cured_thickness is None
                                   else cured_thickness)
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
        overlap = np.where(h > allowance[pose] + OVERLAP_TOLERANCE,
                           np.interp(h, heights, r_env, right=0.0) - rho, -np.inf)
        if not len(overlap) or overlap.max() <= OVERLAP_TOLERANCE:
            continue
        k = int(np.argmax(overlap))
        o = int(obstacle_order[obstacle[k]])
        found.append(Contact(s, KINDS[tp.kind[s]], tuple(float(v) for v in tips[pose[k]]),
                             float(overlap[k]), "part" if o < 0 else f"segment {o}"))
        if limit is not None and len(found) >= limit:
            break
    return found


def _working_layer(tp: Toolpath, s: int, tips: np.ndarray, thickness: np.ndarray) -> np.ndarray:
    """Per pose, the height above the tip plane below which material is what the move works
    on: half the cure's thickness for a cure, and for travel poses within that distance of
    the cure they land on or leave; `WORKING_ALLOWANCE` elsewhere."""
    cure = KINDS.index("cure")
    allowance = np.full(len(tips), WORKING_ALLOWANCE)
    if tp.kind[s] == cure:
        return np.maximum(allowance, thickness[s] / 2.0)
    starts = tp.segment_starts
    for neighbour, point in ((s + 1, tp.points[starts[s + 1] - 1]), (s - 1, tp.points[starts[s] - 1])):
        if 0 <= neighbour < tp.segment_count and tp.kind[neighbour] == cure:
            half = thickness[neighbour] / 2.0
            close = np.linalg.norm(tips - point, axis=1) <= half + ROUNDING_SLACK
            allowance[close] = np.maximum(allowance[close], half)
    return allowance
