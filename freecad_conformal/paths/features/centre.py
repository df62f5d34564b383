"""Where a pattern sits on its face: given parameters, a given point projected onto the face,
or the point whose normal is closest to the build direction (the least tilt).

The facing point is exact: closed forms on planes (the face's centre of mass: every point
faces the same way), spheres (centre + R·up), cylinders and cones
(the meridian facing up, at the middle of the face's axial range); on other faces, or when
the closed form falls outside the trimmed face, the best point of a coarse grid refined by
a Nelder–Mead search of the normal's angle to the build direction (to `ANGLE_TOLERANCE`).
"""
from __future__ import annotations

import math

import numpy as np

from freecad_conformal.errors import PlanError
from freecad_conformal.geometry.faces import domain_grid, face_kind, normals_at, parameters_of, points_at
from freecad_conformal.tolerances import ZERO_LENGTH

#: The refined facing point's normal is within this angle (rad) of the best one.
ANGLE_TOLERANCE = 1e-9
#: The refined point's face parameters settle to this (far below a µm on any real face).
PARAMETER_TOLERANCE = 1e-10
_GRID = 24
_SEEDS = 8


def _on_face(face, uv) -> bool:
    return bool(face.isPartOfDomain(float(uv[0]), float(uv[1])))


def _cost(face, up: np.ndarray, uv) -> float:
    if not _on_face(face, uv):
        return 2.0
    return -float(normals_at(face, np.array([uv]))[0] @ up)


def _closed_form(face, up: np.ndarray) -> list[np.ndarray]:
    kind, surface = face_kind(face), face.Surface
    if kind == "plane":            # one normal everywhere: the middle of the face
        return [parameters_of(face, np.array([tuple(face.CenterOfMass)]))[0]]
    if kind == "sphere":
        centre = np.array(tuple(surface.Center))
        return [parameters_of(face, centre + sign * surface.Radius * up)[0] for sign in (1, -1)]
    if kind in ("cylinder", "cone"):
        axis = np.array(tuple(surface.Axis))
        across = up - (up @ axis) * axis
        if np.linalg.norm(across) < ZERO_LENGTH:
            return []
        across /= np.linalg.norm(across)
        _, _, v0, v1 = face.ParameterRange
        vmid = 0.5 * (v0 + v1)
        mid = points_at(face, np.array([[face.ParameterRange[0], vmid]]))[0]
        centre = np.array(tuple(surface.Center if kind == "cylinder" else surface.Apex))
        along = (mid - centre) @ axis
        out = []
        for sign in (1, -1):
            u = parameters_of(face, centre + along * axis + sign * 10.0 * across)[0][0]
            out.append(np.array([u, vmid]))
        return out
    return []


def facing_point(face, direction) -> tuple[float, float]:
    """(u, v) of the face point whose outward normal is closest to `direction`."""
    up = np.asarray(direction, dtype=float)
    up = up / np.linalg.norm(up)
    candidates = [uv for uv in _closed_form(face, up) if _on_face(face, uv)]
    if candidates:
        best = min(candidates, key=lambda uv: _cost(face, up, uv))
        return float(best[0]), float(best[1])
    from scipy.optimize import minimize
    grid = domain_grid(face, _GRID)
    if not len(grid):
        raise PlanError("the face has no interior point to centre a pattern on")
    # several seeds: a wavy face has local optima
    seeds = grid[np.argsort(-(normals_at(face, grid) @ up))[:_SEEDS]]
    best, best_cost = seeds[0], _cost(face, up, seeds[0])
    for seed in seeds:
        result = minimize(lambda uv: _cost(face, up, uv), seed, method="Nelder-Mead",
                          options={"xatol": PARAMETER_TOLERANCE, "fatol": ANGLE_TOLERANCE ** 2,
                                   "maxiter": 2000})
        if result.fun < best_cost:
            best, best_cost = result.x, float(result.fun)
    return float(best[0]), float(best[1])


def pattern_centre(face, at, at_point, build_direction, what: str) -> tuple[float, float]:
    """The pattern's (u, v): `at` as given, `at_point` (x, y, z) projected onto the face, or
    the facing point of the build direction."""
    if at and at_point:
        raise PlanError(f"{what}: give --at (u,v) or --at-point (x,y,z), not both")
    if at:
        if len(at) != 2:
            raise PlanError(f"{what}: --at takes two face parameters u,v, got {list(at)}")
        return float(at[0]), float(at[1])
    if at_point:
        if len(at_point) != 3:
            raise PlanError(f"{what}: --at-point takes x,y,z, got {list(at_point)}")
        uv = parameters_of(face, np.array([at_point], dtype=float))[0]
        if not _on_face(face, uv):
            raise PlanError(f"{what}: the point {tuple(at_point)} projects outside the face")
        distance = float(np.linalg.norm(points_at(face, np.array([uv]))[0] - np.asarray(at_point)))
        if not math.isfinite(distance):
            raise PlanError(f"{what}: cannot project {tuple(at_point)} onto the face")
        return float(uv[0]), float(uv[1])
    return facing_point(face, build_direction)
