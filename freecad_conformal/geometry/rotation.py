"""Axis–angle rotations (Rodrigues) that bring a build direction to the machine's build axis.

Pure numpy: METHODS section 4 rotates each sub-part so its base rests on what is printed,
with R = cosθ·I + sinθ·[n]× + (1 − cosθ)·n nᵀ.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

from freecad_conformal.errors import PlanError
from freecad_conformal.tolerances import ZERO_LENGTH

#: Two unit vectors whose dot product is within this of ±1 are treated as (anti)parallel:
#: the cross product is then shorter than ~1.4e-6 and no longer defines an axis reliably.
PARALLEL_DOT = 1.0 - 1e-12

#: Axes tried, in order, for a half turn (direction opposite the build axis): the first one
#: perpendicular to the direction. Y first matches METHODS section 3 ("180° about Y").
HALF_TURN_AXES = (np.array([0.0, 1.0, 0.0]), np.array([1.0, 0.0, 0.0]))


def _unit(vector: Sequence[float], what: str) -> np.ndarray:
    array = np.asarray(vector, dtype=float).reshape(-1)
    if array.shape != (3,) or not np.all(np.isfinite(array)):
        raise PlanError(f"{what} must be three finite numbers, got {list(np.ravel(vector))!r}")
    length = float(np.linalg.norm(array))
    if length < ZERO_LENGTH:
        raise PlanError(f"{what} must not be the zero vector")
    return array / length


def rodrigues_matrix(axis: Sequence[float], angle: float) -> np.ndarray:
    """The 3×3 rotation by `angle` (rad, right hand) about the unit `axis`."""
    n = _unit(axis, "rotation axis")
    cross = np.array([[0.0, -n[2], n[1]], [n[2], 0.0, -n[0]], [-n[1], n[0], 0.0]])
    return (np.cos(angle) * np.eye(3) + np.sin(angle) * cross
            + (1.0 - np.cos(angle)) * np.outer(n, n))


def rotation_to(direction: Sequence[float],
                target: Sequence[float] = (0.0, 0.0, 1.0)) -> tuple[np.ndarray, float]:
    """(axis, angle) of the shortest rotation taking `direction` onto `target`.

    Parallel: angle 0 about the target. Opposite: a half turn about the first of Y, X
    perpendicular to the direction (for the +Z build axis: -Z turns 180° about Y).
    """
    d = _unit(direction, "build direction")
    t = _unit(target, "machine build axis")
    dot = float(np.clip(d @ t, -1.0, 1.0))
    if dot >= PARALLEL_DOT:
        return t.copy(), 0.0
    if dot <= -PARALLEL_DOT:
        for axis in HALF_TURN_AXES:
            if abs(axis @ d) < 1e-9:
                return axis.copy(), float(np.pi)
        axis = np.cross(d, HALF_TURN_AXES[0])
        return axis / np.linalg.norm(axis), float(np.pi)
    axis = np.cross(d, t)
    return axis / np.linalg.norm(axis), float(np.arccos(dot))


def rotate_points(points: np.ndarray, axis: Sequence[float], angle: float,
                  centre: Sequence[float] = (0.0, 0.0, 0.0)) -> np.ndarray:
    """Points (N, 3) rotated by `angle` about the line through `centre` along `axis`."""
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    c = np.asarray(centre, dtype=float)
    return (pts - c) @ rodrigues_matrix(axis, angle).T + c
