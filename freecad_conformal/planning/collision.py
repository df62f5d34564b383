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

from freecad_conformal.process.tools import Envelope

#: Deposit height above the surface (mm): the nozzle tip sits one layer above what it lays
#: on, so the surface it deposits onto is not reported as a collision.
DEFAULT_STANDOFF = 0.2

#: Spacing of surface samples as a fraction of the envelope's body diameter: a tenth keeps a
#: body collision from slipping between samples (the body is what meets walls, METHODS 4)
#: while the pairwise test stays well under a second; never finer than MIN_SPACING.
SPACING_FRACTION = 0.1
MIN_SPACING = 1.0

#: Triangulation deflection (mm) used to sample surfaces; curved faces are followed to 0.05 mm.
SAMPLE_DEFLECTION = 0.05


def surface_points(shape, spacing: float = MIN_SPACING) -> np.ndarray:
    """Points (N, 3) spread over the shape's surface no farther than ~`spacing` apart."""
    points, triangles = shape.tessellate(SAMPLE_DEFLECTION)
    if not triangles:
        return np.array([tuple(v.Point) for v in shape.Vertexes], dtype=float).reshape(-1, 3)
    pts = np.array([tuple(p) for p in points])
    tri = np.asarray(triangles, dtype=int)
    a, b, c = pts[tri[:, 0]], pts[tri[:, 1]], pts[tri[:, 2]]
    longest = np.max([np.linalg.norm(b - a, axis=1), np.linalg.norm(c - b, axis=1),
                      np.linalg.norm(a - c, axis=1)], axis=0)
    levels = np.maximum(1, np.ceil(longest / spacing)).astype(int)
    samples = [pts]
    for k in np.unique(levels):
        chosen = levels == k
        i, j = np.meshgrid(np.arange(k + 1), np.arange(k + 1), indexing="ij")
        keep = (i + j) <= k
        wa, wb = (i[keep] / k), (j[keep] / k)
        wc = 1.0 - wa - wb
        grid = (wa[None, :, None] * a[chosen][:, None, :] + wb[None, :, None] * b[chosen][:, None, :]
                + wc[None, :, None] * c[chosen][:, None, :])
        samples.append(grid.reshape(-1, 3))
    return np.unique(np.round(np.vstack(samples), 9), axis=0)


def envelope_hits(tool_points: np.ndarray, axis: np.ndarray, envelope: Envelope,
                  obstacle: np.ndarray, chunk: int = 2048) -> np.ndarray:
    """Mask over `obstacle` points lying inside the envelope placed at any tool point."""
    d = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    length = envelope.tip_length + envelope.body_length
    hit = np.zeros(len(obstacle), dtype=bool)
    if len(obstacle) == 0 or len(tool_points) == 0:
        return hit
    # Only obstacle points within reach of some tool point can be hit (cheap box filter).
    reach = length + envelope.body_diameter
    low, high = tool_points.min(axis=0) - reach, tool_points.max(axis=0) + reach
    near = np.all((obstacle >= low) & (obstacle <= high), axis=1)
    candidates = np.nonzero(near)[0]
    for start in range(0, len(candidates), chunk):
        index = candidates[start:start + chunk]
        rel = obstacle[index][None, :, :] - tool_points[:, None, :]
        s = rel @ d
        radial = np.linalg.norm(rel - s[..., None] * d, axis=2)
        tip = (envelope.tip_diameter + (envelope.body_diameter - envelope.tip_diameter)
               * np.clip(s / envelope.tip_length, 0, 1) if envelope.tip_length > 0
               else np.full_like(s, envelope.body_diameter)) / 2
        inside = (s >= 0) & (s <= length) & (radial < tip)
        hit[index] |= inside.any(axis=0)
    return hit


class CollisionChecker:
    """Samples each sub-part once; answers which built sub-parts the tool would hit."""

    def __init__(self, shapes: list, directions: list[np.ndarray], envelope: Envelope,
                 standoff: float = DEFAULT_STANDOFF, spacing: float | None = None) -> None:
        self.envelope = envelope
        self.directions = [np.asarray(d, dtype=float) for d in directions]
        step = spacing if spacing is not None else max(MIN_SPACING,
                                                       SPACING_FRACTION * envelope.body_diameter)
        if not (math.isfinite(step) and step > 0):
            raise ValueError(f"sample spacing must be a positive length, got {step!r}")
        self.points = [surface_points(shape, step) for shape in shapes]
        self.standoff = standoff
        self._cache: dict[tuple[int, int], bool] = {}

    def hits(self, index: int, built: list[int]) -> list[int]:
        """Built sub-parts the envelope meets while sub-part `index` is deposited."""
        return [other for other in built if self._hits_one(index, other)]

    def _hits_one(self, index: int, other: int) -> bool:
        key = (index, other)
        if key not in self._cache:
            d = self.directions[index]
            tool_points = self.points[index] + self.standoff * d
            self._cache[key] = bool(envelope_hits(tool_points, d, self.envelope,
                                                  self.points[other]).any())
        return self._cache[key]
