"""(u, v) of a point on a B-spline surface by Newton's method from a sampled grid.

OCC's `Surface.parameter` searches the whole surface for every point (0.75 ms a call on a
modelled screw thread: 65 of its 141 s of planning). A point the face-by-face section asks
about lies on the surface already, so the nearest of a grid of surface samples is a start
from which a few Newton steps on |S(u, v) − p|² converge; a point they do not bring onto
the surface goes to OCC.
"""
from __future__ import annotations

import numpy as np

#: Samples per parameter direction of the starting grid: at least GRID, and
#: SAMPLES_PER_POLE per pole (a thread's surface winds round a dozen times along v, 137
#: poles: with 24 samples the nearest one was often on the wrong turn), at most GRID_MAX.
GRID = 24
SAMPLES_PER_POLE = 3
GRID_MAX = 400

#: Newton steps at most.
MAX_STEPS = 8

#: A projection is accepted when the surface point lies this close (mm) to the given one:
#: the points asked about are on the surface to OCC's walking precision (~1e-7 mm).
ON_SURFACE = 1e-6


class SurfaceProjector:
    """Projects points of one (bounded) surface onto its parameters."""

    def __init__(self, surface) -> None:
        self.surface = surface
        # The whole surface, not the face's range: the section asks about points of
        # plane ∩ surface curves that lie beyond the face too (and are outside it).
        u0, u1, v0, v1 = surface.bounds()
        self._low, self._high = np.array([u0, v0]), np.array([u1, v1])
        us = np.linspace(u0, u1, _samples(surface.NbUPoles))
        vs = np.linspace(v0, v1, _samples(surface.NbVPoles))
        self._uv = np.array([(u, v) for u in us for v in vs])
        xyz = np.array([tuple(surface.value(float(u), float(v))) for u, v in self._uv])
        # One contiguous array per coordinate: the nearest sample is found without (N, 3)
        # temporaries (a blade's grid: 70 us a point as rows).
        self._columns = [np.ascontiguousarray(xyz[:, k]) for k in range(3)]

    def parameter(self, point) -> tuple[float, float]:
        """(u, v) of a point on the surface (a FreeCAD Vector)."""
        p = np.array(tuple(point))
        uv = self._uv[int(np.argmin(self._squared_distances(p)))].copy()
        surface = self.surface
        for _ in range(MAX_STEPS):
            u, v = float(uv[0]), float(uv[1])
            r = p - np.array(tuple(surface.value(u, v)))
            if r @ r < ON_SURFACE ** 2:
                return u, v
            su = np.array(tuple(surface.getDN(u, v, 1, 0)))
            sv = np.array(tuple(surface.getDN(u, v, 0, 1)))
            normal = np.array([[su @ su, su @ sv], [su @ sv, sv @ sv]])
            try:
                step = np.linalg.solve(normal, np.array([su @ r, sv @ r]))
            except np.linalg.LinAlgError:
                break
            uv = np.clip(uv + step, self._low, self._high)
        u, v = surface.parameter(point)
        return float(u), float(v)

    def _squared_distances(self, p: np.ndarray) -> np.ndarray:
        """|sample − p|² per grid sample, summed x, y, z in that order as a row sum adds
        them (the same values, so the same nearest sample)."""
        x, y, z = self._columns
        d = x - p[0]
        total = d * d
        d = y - p[1]
        d *= d
        total += d
        d = z - p[2]
        d *= d
        total += d
        return total


def _samples(poles: int) -> int:
    return int(min(max(GRID, SAMPLES_PER_POLE * poles), GRID_MAX))
