"""Tool-envelope collision check against material already built (METHODS section 3).

The envelope (process/tools.py) is a cone tip widening to a cylinder body along the tool
axis, which points along the sub-part's build direction. Building sub-part S collides with
the built body B_dep when the envelope, placed at any point where S is deposited, meets
B_dep. Both sides are sampled on their surfaces at a stated spacing (an envelope that meets
a solid without containing its tip must cross its surface), and point-in-envelope is exact.
"""
from __future__ import annotations

import math

import numpy as np

from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry.frames import index_rows, perpendicular_frame, points_array
from freecad_conformal.geometry.surface_mesh import made_mesh
from freecad_conformal.process.tools import Envelope
from freecad_conformal.tolerances import BASE_LEVEL_TOLERANCE, SAME_DIRECTION_ANGLE

#: Deposit height above the surface (mm): the nozzle tip sits one layer above what it lays
#: on, so the surface it deposits onto is not reported as a collision.
DEFAULT_STANDOFF = 0.2

#: Spacing of surface samples as a fraction of the envelope's body diameter: a tenth keeps a
#: body collision from slipping between samples (the body is what meets walls, METHODS 4)
#: while the pairwise test stays well under a second; never finer than MIN_SPACING.
SPACING_FRACTION = 0.1
MIN_SPACING = 1.0

SAME_DIRECTION = SAME_DIRECTION_ANGLE
#: Base levels closer than this (mm) are one level; the samples include the vertices, so
#: the lowest sample of a flat-bottomed sub-part is its base level to rounding.
LEVEL_TOLERANCE = BASE_LEVEL_TOLERANCE

#: Obstacle × tool point pairs tested in one numpy block (bounds the memory to ~100 MB).
PAIRS_PER_BLOCK = 2_000_000

#: Triangulation deflection (mm) used to sample surfaces; curved faces are followed to 0.05 mm.
SAMPLE_DEFLECTION = 0.05
#: A mesh the decomposition made of the shape already (geometry/surface_mesh.py) is sampled
#: instead when its chord error is within this (mm): a fifth of the finest spacing
#: (MIN_SPACING), so the samples stay closer to the surface than the half spacing an
#: envelope may already reach between them. No second mesh, and no MeshPart import: the
#: jack's whole plan 2.94 -> 2.48 s, CrankArm's 16.2 -> 15.8 s (its sub-parts laid out on
#: the platform carry their originals' meshes: surface_mesh.seed_moved_mesh), the same G-code.
REUSED_DEFLECTION = 0.2
#: BRepMesh's angular deflection (rad) for the samples. The chord error SAMPLE_DEFLECTION
#: already bounds how far they lie from the surface, and the triangles are split down to the
#: spacing anyway; FreeCAD's `tessellate` adds 0.1 rad, which made 139,000 triangles of the
#: fan's lofted blades (1.0 s of its build order) where 0.5 rad makes 13,000 (0.1 s), their
#: centres within 0.03 mm of the surface.
SAMPLE_ANGLE = 0.5


def surface_points(shape, spacing: float = MIN_SPACING) -> np.ndarray:
    """Points (N, 3) spread over the shape's surface no farther than ~`spacing` apart: from
    the shape's own mesh where one was made fine enough (REUSED_DEFLECTION), else from a
    copy meshed at SAMPLE_DEFLECTION."""
    made = made_mesh(shape)
    if made is not None and made.deflection <= REUSED_DEFLECTION:
        pts, tri = made.points, made.triangles
    else:
        points, triangles = _triangulated(shape)
        pts = points_array(points)
        tri = index_rows(triangles)
    if not len(tri):
        return np.array([tuple(v.Point) for v in shape.Vertexes], dtype=float).reshape(-1, 3)
    return spread_samples(pts, pts[tri], spacing)


def spread_samples(points: np.ndarray, corners: np.ndarray, spacing: float) -> np.ndarray:
    """`points` and points spread over the triangles `corners` (T, 3, 3) no farther than
    ~`spacing` apart, one kept per cell of a quarter spacing."""
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    longest = np.max([np.linalg.norm(b - a, axis=1), np.linalg.norm(c - b, axis=1),
                      np.linalg.norm(a - c, axis=1)], axis=0)
    levels = np.maximum(1, np.ceil(longest / spacing)).astype(int)
    samples = [points]
    for k in np.unique(levels):
        chosen = levels == k
        i, j = np.meshgrid(np.arange(k + 1), np.arange(k + 1), indexing="ij")
        keep = (i + j) <= k
        wa, wb = (i[keep] / k), (j[keep] / k)
        wc = 1.0 - wa - wb
        grid = (wa[None, :, None] * a[chosen][:, None, :] + wb[None, :, None] * b[chosen][:, None, :]
                + wc[None, :, None] * c[chosen][:, None, :])
        samples.append(grid.reshape(-1, 3))
    points = np.vstack(samples)
    # Triangles share edges, so their grids repeat points: keep one point per cell of a
    # quarter spacing (a 1-D key sorts far faster than unique rows).
    keys = np.floor((points - points.min(axis=0)) / (spacing / 4)).astype(np.int64)
    span = keys.max(axis=0) + 1
    flat = (keys[:, 0] * span[1] + keys[:, 1]) * span[2] + keys[:, 2]
    return points[np.unique(flat, return_index=True)[1]]


def _triangulated(shape) -> tuple[list, list]:
    """(nodes, triangles) of a copy of `shape` meshed at SAMPLE_DEFLECTION and SAMPLE_ANGLE.

    On a copy: re-meshing the shape itself would leave its faces' edges unlike their
    neighbours' in other meshes of it (geometry/surface_mesh.py). MeshPart is the binding
    that takes the angle; `tessellate` then reads the copy's triangles back in double
    precision (the mesh object holds floats) without meshing again.
    """
    import_freecad()
    import MeshPart  # after FreeCAD: imported first it crashes a plain Python

    copy = shape.copy()
    MeshPart.meshFromShape(Shape=copy, LinearDeflection=SAMPLE_DEFLECTION,
                           AngularDeflection=SAMPLE_ANGLE, Relative=False)
    return copy.tessellate(SAMPLE_DEFLECTION)


def _cells(uv: np.ndarray, size: float) -> dict[tuple[int, int], np.ndarray]:
    """Indices of the points in each square cell of side `size` of the plane ⊥ the axis."""
    keys = np.floor(uv / size).astype(np.int64)
    order = np.lexsort((keys[:, 1], keys[:, 0]))
    keys = keys[order]
    starts = np.nonzero(np.any(np.diff(keys, axis=0) != 0, axis=1))[0] + 1
    groups = np.split(order, starts)
    return {(int(keys[s, 0]), int(keys[s, 1])): g
            for s, g in zip(np.concatenate([[0], starts]), groups) if len(g)}


def envelope_hits(tool_points: np.ndarray, axis: np.ndarray, envelope: Envelope,
                  obstacle: np.ndarray, first_only: bool = False) -> np.ndarray:
    """Mask over `obstacle` points lying inside the envelope placed at any tool point.

    Points are binned in the plane ⊥ the axis in cells as wide as the envelope's largest
    radius, so an obstacle point is only tested against tool points in its own and the eight
    neighbouring cells (the envelope cannot reach farther); `first_only` stops at the first
    hit (the caller only asks whether there is one).
    """
    d = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    hit = np.zeros(len(obstacle), dtype=bool)
    if len(obstacle) == 0 or len(tool_points) == 0:
        return hit
    length = envelope.tip_length + envelope.body_length
    radius = envelope.body_diameter / 2
    frame = perpendicular_frame(d)
    tool_s, obstacle_s = tool_points @ d, obstacle @ d
    tool_uv, obstacle_uv = tool_points @ frame.T, obstacle @ frame.T
    # Only obstacle points within reach of some tool point can be hit (cheap box filter).
    near = ((obstacle_s >= tool_s.min()) & (obstacle_s <= tool_s.max() + length)
            & np.all(obstacle_uv >= tool_uv.min(axis=0) - radius, axis=1)
            & np.all(obstacle_uv <= tool_uv.max(axis=0) + radius, axis=1))
    if not near.any():
        return hit
    candidates = np.nonzero(near)[0]
    tool_cells = _cells(tool_uv, radius)
    for (i, j), local in _cells(obstacle_uv[candidates], radius).items():
        index = candidates[local]
        tools = [tool_cells[(i + a, j + b)] for a in (-1, 0, 1) for b in (-1, 0, 1)
                 if (i + a, j + b) in tool_cells]
        if not tools:
            continue
        near_tools = np.concatenate(tools)
        low, high = obstacle_s[index].min() - length, obstacle_s[index].max()
        near_tools = near_tools[(tool_s[near_tools] >= low) & (tool_s[near_tools] <= high)]
        if len(near_tools) == 0:
            continue
        rows = max(1, PAIRS_PER_BLOCK // len(near_tools))
        for start in range(0, len(index), rows):
            block = index[start:start + rows]
            hit[block] |= _inside(obstacle_s[block], obstacle_uv[block], tool_s[near_tools],
                                  tool_uv[near_tools], envelope)
            if first_only and hit.any():
                return hit
    return hit


def _inside(obstacle_s, obstacle_uv, tool_s, tool_uv, envelope: Envelope) -> np.ndarray:
    """Mask over obstacle points inside the envelope at any of the tool points."""
    s = obstacle_s[:, None] - tool_s[None, :]
    gap = obstacle_uv[:, None, :] - tool_uv[None, :, :]
    radial2 = np.einsum("ijk,ijk->ij", gap, gap)
    if envelope.tip_length > 0:
        r = (envelope.tip_diameter + (envelope.body_diameter - envelope.tip_diameter)
             * np.clip(s / envelope.tip_length, 0, 1)) / 2
    else:
        r = np.full_like(s, envelope.body_diameter / 2)
    inside = (s >= 0) & (s <= envelope.tip_length + envelope.body_length) & (radial2 < r * r)
    return inside.any(axis=1)


def sample_spacing(envelope: Envelope) -> float:
    """The spacing (mm) of the surface samples checked against `envelope` (SPACING_FRACTION)."""
    return max(MIN_SPACING, SPACING_FRACTION * envelope.body_diameter)


def builds_into(samples: np.ndarray, direction: np.ndarray, envelope: Envelope,
                obstacle: np.ndarray, standoff: float = DEFAULT_STANDOFF) -> bool:
    """Whether the envelope, depositing at the surface `samples` of what is built along
    `direction` (the tool point `standoff` above each), meets any `obstacle` sample."""
    d = np.asarray(direction, dtype=float)
    return bool(envelope_hits(samples + standoff * d, d, envelope, obstacle,
                              first_only=True).any())


def concurrent(d: np.ndarray, level: float, e: np.ndarray, other_level: float) -> bool:
    """Whether sub-parts built along `d` and `e` from base levels `level`, `other_level` are
    one direction from one level: the toolpath lays them together layer by layer
    (paths.assemble), the nozzle never sits below material of either, so they cannot collide
    with each other."""
    d, e = np.asarray(d, dtype=float), np.asarray(e, dtype=float)
    same = float(d @ e) / (np.linalg.norm(d) * np.linalg.norm(e)) > math.cos(SAME_DIRECTION)
    return same and abs(level - other_level) < LEVEL_TOLERANCE


class CollisionChecker:
    """Samples each sub-part once; answers which built sub-parts the tool would hit."""

    def __init__(self, shapes: list, directions: list[np.ndarray], envelope: Envelope,
                 standoff: float = DEFAULT_STANDOFF, spacing: float | None = None) -> None:
        self.envelope = envelope
        self.directions = [np.asarray(d, dtype=float) for d in directions]
        step = spacing if spacing is not None else sample_spacing(envelope)
        if not (math.isfinite(step) and step > 0):
            raise ValueError(f"sample spacing must be a positive length, got {step!r}")
        self._shapes, self._step = list(shapes), step
        # Sampled when first asked: a plan of one sub-part asks nothing (Pump_Nut's and
        # every whole orientation's 0.06-0.08 s of meshing at SAMPLE_DEFLECTION).
        self._points: dict[int, np.ndarray] = {}
        self._levels: dict[int, float] = {}
        self.standoff = standoff
        self._cache: dict[tuple[int, int], bool] = {}

    def points(self, index: int) -> np.ndarray:
        """Surface samples (N, 3) of sub-part `index`."""
        if index not in self._points:
            self._points[index] = surface_points(self._shapes[index], self._step)
        return self._points[index]

    def level(self, index: int) -> float:
        """Base level of sub-part `index` along its build direction (its lowest sample)."""
        if index not in self._levels:
            found = self.points(index)
            self._levels[index] = (float(np.min(found @ self.directions[index]))
                                   if len(found) else 0.0)
        return self._levels[index]

    def hits(self, index: int, built: list[int]) -> list[int]:
        """Built sub-parts the envelope meets while sub-part `index` is deposited."""
        return [other for other in built if self._hits_one(index, other)]

    def concurrent_with(self, index: int, other: int) -> bool:
        """Whether the two sub-parts are built together, layer by layer (`concurrent`)."""
        return concurrent(self.directions[index], self.level(index),
                          self.directions[other], self.level(other))

    def _hits_one(self, index: int, other: int) -> bool:
        key = (index, other)
        if self.concurrent_with(index, other):
            return False
        if key not in self._cache:
            self._cache[key] = builds_into(self.points(index), self.directions[index],
                                           self.envelope, self.points(other), self.standoff)
        return self._cache[key]
