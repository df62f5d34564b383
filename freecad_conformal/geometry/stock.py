"""The material a hybrid plan leaves, checked against the part at points of its surface.

Deposited nominal layers and the volumes the milling passes sweep are both prisms: a 2D
region in a frame, from a bottom height along the frame's normal for a height (`Prism`);
each carries its place in time (`order`): a session mills only what was deposited before
it. A point is in the result when a deposit holds it and no later sweep does.

The check samples the part's surface (a grid across every face, exact normals) and moves
each point a set of distances out and in along the normal: a point outside the part that
is in the result is stock left standing that far proud; a point inside the part that is
not in the result is a gouge (or a shortfall) that deep (in or out of the part: OCC's
exact classifier, or on free-form parts where it is slow the fine mesh's, whose answer
differs only within 0.01 mm of the surface, `geometry/inside.py`). "Within 0.05 mm everywhere" is
then: no point 0.05 mm out is in the result and every point 0.05 mm in is. Membership is
decided in each prism's own frame with shapely's point-in-polygon tests, robustly and all
points at once; an earlier version took OCC Booleans of the prisms, and on the 45° branch
their results were wrong (a cut grew its solid; a Monte Carlo count of the same
intersection gave 0.004 mm³ where the Boolean removed 12 mm³).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np
import shapely

from freecad_conformal.geometry.frames import LayerFrame
from freecad_conformal.geometry.shape_cache import ShapeCache

#: Distances (mm) each surface point is moved out and in: the finishing tolerance first,
#: then coarser steps that say how far stock or a gouge reaches.
OFFSETS = (0.05, 0.1, 0.25, 0.5, 1.0, 2.0, 5.0)

#: Spacing (mm) of the sample grid on each face (at least a few points per face).
SAMPLE_SPACING = 0.5

#: Samples per face at most (a large face is sampled more sparsely).
MAX_FACE_SAMPLES = 4000


@dataclass
class Prism:
    """A region (shapely, frame coordinates) from `bottom` along frame.n for `height`.
    `order` places it in time: a deposit made after `order` milling sessions, or the
    volume swept in session `order` (a session cuts what was deposited before it only)."""

    frame: LayerFrame
    region: object
    bottom: float
    height: float
    order: int = 0

    def holds(self, points: np.ndarray) -> np.ndarray:
        """(n,) whether each point lies in the prism (boundary included)."""
        h = points @ self.frame.n
        inside = (h >= self.bottom - 1e-9) & (h <= self.bottom + self.height + 1e-9)
        if not inside.any():
            return inside
        uv = self.frame.to_2d(points[inside])
        result = np.zeros(len(points), dtype=bool)
        result[np.flatnonzero(inside)] = shapely.intersects_xy(self.region, uv[:, 0], uv[:, 1])
        return result

    @property
    def volume(self) -> float:
        return float(self.region.area) * self.height


@dataclass
class MaterialCheck:
    """What the plan leaves against the part: deposited volume (mm³), surface points
    checked, and how far stock stands proud (`max_uncut`) and a gouge reaches in
    (`max_gouge`), each the largest sampled offset found (0 when none at 0.05 mm);
    `uncut_points`, `gouge_points` count the points failing at the tolerance."""

    deposited: float
    points: int
    uncut_points: int
    gouge_points: int
    max_uncut: float
    max_gouge: float
    #: per offset (mm): (points with stock that far out, points gouged that deep)
    by_offset: dict = field(default_factory=dict)
    #: of `uncut_points`, those outside every concave corner's zone that a cutter of the
    #: finishing radius cannot reach (`corner_zones`); None when no radius was given
    uncut_outside_corners: int | None = None

    @property
    def max_deviation(self) -> float:
        return max(self.max_uncut, self.max_gouge)


def in_result(points: np.ndarray, deposits: Sequence[Prism], sweeps: Sequence[Prism]) -> np.ndarray:
    """(n,) whether each point is deposited and not milled away afterwards."""
    # the last deposit that holds a point counts: a nominal 3-D layer stands above its top
    # plane where the next layers go; faced away, that space is deposited again
    order = np.full(len(points), -1)
    for prism in deposits:
        held = prism.holds(points)
        order[held] = np.maximum(order[held], prism.order)
    kept = order >= 0
    for sweep in sweeps:
        candidates = np.flatnonzero(kept & (order <= sweep.order))
        if len(candidates):
            kept[candidates[sweep.holds(points[candidates])]] = False
    return kept


def surface_samples(part, spacing: float = SAMPLE_SPACING) -> tuple[np.ndarray, np.ndarray]:
    """(points, outward unit normals) on a grid across every face of `part` (read-only:
    a hybrid plan's last passes and its check sample the same part, once)."""
    if spacing != SAMPLE_SPACING:
        return _sampled(part, spacing)
    return _SAMPLES.get((part,), lambda: _sampled(part, spacing))


def _sampled(part, spacing: float) -> tuple[np.ndarray, np.ndarray]:
    points, normals = [], []
    for face in part.Faces:
        u0, u1, v0, v1 = face.ParameterRange
        area = max(float(face.Area), 1e-9)
        count = int(np.clip(np.sqrt(area) / spacing, 3, np.sqrt(MAX_FACE_SAMPLES)))
        steps = (np.arange(count) + 0.5) / count
        for u in u0 + (u1 - u0) * steps:
            for v in v0 + (v1 - v0) * steps:
                if not face.isPartOfDomain(u, v):
                    continue
                points.append(tuple(face.valueAt(u, v)))
                normals.append(tuple(face.normalAt(u, v)))
    n = np.array(normals, dtype=float).reshape(-1, 3)
    n /= np.maximum(np.linalg.norm(n, axis=1), 1e-12)[:, None]
    p = np.array(points, dtype=float).reshape(-1, 3)
    p.flags.writeable = n.flags.writeable = False
    return p, n


#: Samples of the last parts asked, by shape.
_SAMPLES: ShapeCache[tuple[np.ndarray, np.ndarray]] = ShapeCache(limit=8, oriented=True)


def check_material(part, deposits: Sequence[Prism], sweeps: Sequence[Prism],
                   offsets: Sequence[float] = OFFSETS,
                   corner_radius: float | None = None) -> MaterialCheck:
    """The result of `deposits` less later `sweeps` against `part` (see the module);
    `corner_radius`: the finishing cutter's radius, to tell stock in the corners no such
    cutter reaches from stock elsewhere."""
    from freecad_conformal.geometry.inside import inside_test

    inside = inside_test(part)
    points, normals = surface_samples(part)
    by_offset = {}
    max_uncut = max_gouge = 0.0
    outside = None
    for offset in offsets:
        out = points + offset * normals
        inward = points - offset * normals
        # a point moved out can land inside the part again (a thin wall, a slot): only
        # points that really left it count as stock, and only points inside as gouge
        # (asked for the suspects only; `geometry/inside.py` answers exactly where OCC is
        # quick, from the fine mesh where it is not)
        suspects = np.flatnonzero(in_result(out, deposits, sweeps))
        left = suspects[~inside(out[suspects], True)]
        proud = len(left)
        if outside is None and corner_radius is not None:
            zones = corner_zones(part, corner_radius)
            outside = sum(not _in_zone(points[k], zones) for k in left)
        suspects = np.flatnonzero(~in_result(inward, deposits, sweeps))
        sunk = int(inside(inward[suspects], False).sum())
        by_offset[offset] = (proud, sunk)
        if proud:
            max_uncut = offset
        if sunk:
            max_gouge = offset
    first = by_offset[offsets[0]]
    return MaterialCheck(deposited=float(sum(p.volume for p in deposits)), points=len(points),
                         uncut_points=first[0], gouge_points=first[1], max_uncut=max_uncut,
                         max_gouge=max_gouge, by_offset=by_offset,
                         uncut_outside_corners=outside)


#: A point counts as in a corner's zone to this (mm) past its depth: the sample grid's
#: points sit on faces, the zone's edge is where the cutter's circle touches them.
ZONE_SLACK = 0.1


def corner_zones(part, radius: float) -> list[tuple[object, float]]:
    """(edge, depth) of each concave edge of `part`: a cylinder of `radius` in the edge's
    wedge (opening 2π − inner angle) touches the faces `radius · cot(opening / 2)` from the
    edge at the nearest, so stock within that distance stays whatever the cutter's axis
    in planes across the edge (a 45° wedge and a 6 mm cutter: 7.24 mm)."""
    from freecad_conformal.geometry.concave_edges import concave_edges

    zones = []
    for found in concave_edges(part):
        opening = 2.0 * math.pi - found.inner_angle
        if opening <= 0:
            continue
        zones.append((found.edge, radius / math.tan(0.5 * opening)))
    return zones


def _in_zone(point: np.ndarray, zones) -> bool:
    """Whether `point` lies within a zone's depth of its edge (boxes first: the exact
    distance costs a millisecond)."""
    from freecad_conformal.freecad_env import import_freecad

    App, Part = import_freecad()
    vertex = None
    for edge, depth in zones:
        box, reach = edge.BoundBox, depth + ZONE_SLACK
        if any(point[k] < low - reach or point[k] > high + reach
               for k, (low, high) in enumerate(((box.XMin, box.XMax), (box.YMin, box.YMax),
                                                (box.ZMin, box.ZMax)))):
            continue
        vertex = vertex or Part.Vertex(App.Vector(*point))
        if edge.distToShape(vertex)[0] <= reach:
            return True
    return False
