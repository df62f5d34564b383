"""Ball-end finishing of a part's curved faces ("3+2": one tool axis per face).

Contour passes finish walls along a build direction and "3+2" passes finish leaning planar
faces; a dome, a torus or a free-form face keeps its stair steps under them. A ball end
mill listed among the mill tools finishes such faces: passes follow iso-parameter lines of
the face, `scallop_stepover` apart on the surface (a 6 mm ball leaves cusps under
`SCALLOP` between neighbours on a flat; less on a convex face), points `POINT_SPACING`
apart along each. The ball's centre stands the ball's radius out along the face's exact
normal at each point, so the ball touches the face there whatever the tool axis. A face
takes one axis, of the build directions and its mean normal, that reaches most of it
(its normals within `MAX_NORMAL_ANGLE`: the ball's lower half touches), then more for what
leans past (`face_axes`), never from under the platform.

A point is kept only if its ball reaches no sampled surface point of the part (a concave
curve tighter than the ball, a neighbouring face), nor the shank or holder above it; what
is left out stays as stock and the material check reports it. The volume a pass removes
is its ball swept along the centres (`BallSweep`), what the material check subtracts.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from freecad_conformal.geometry.face_normals import plane_normal
from freecad_conformal.paths.milling import MillPass, MillTool

#: Cusp height (mm) left between neighbouring passes on a flat: under the 0.05 mm
#: finishing tolerance with room for the sampling of the check.
SCALLOP = 0.04

#: Spacing (mm) of a pass's points: a 6 mm ball's chord between them cuts into a convex
#: face of 10 mm radius by 0.5² / (8 · 13) ≈ 0.002 mm.
POINT_SPACING = 0.5

#: A ball or shank may come this close (mm) inside a sampled surface point: the face the
#: ball finishes is touched, not cut.
GOUGE_SLACK = 0.005

#: A point is finished only where its normal lies within this of the tool axis: the ball's
#: lower half touches it (at 90°, its equator); past it the shank would.
MAX_NORMAL_ANGLE = math.radians(90.0)

#: Parameter grid (per direction) on which a face's normals and spacings are read.
GRID = 24

#: Points of the part's surface checked against one chunk of ball positions at a time.
CHUNK = 64


@dataclass
class BallSweep:
    """The volume a ball of `radius` sweeps along `centres` (n, 3), in session `order`."""

    centres: np.ndarray
    radius: float
    order: int = 0

    def holds(self, points: np.ndarray) -> np.ndarray:
        """(m,) whether each point lies within the ball's radius of the centres' polyline."""
        points = np.asarray(points, dtype=float)
        held = np.zeros(len(points), dtype=bool)
        low = self.centres.min(axis=0) - self.radius
        high = self.centres.max(axis=0) + self.radius
        near = np.flatnonzero(np.all((points >= low) & (points <= high), axis=1))
        if not len(near):
            return held
        q = points[near]
        a, b = self.centres[:-1], self.centres[1:]
        if not len(a):
            a = b = self.centres
        d = b - a
        length2 = np.maximum((d * d).sum(axis=1), 1e-18)
        inside = np.zeros(len(q), dtype=bool)
        for start in range(0, len(a), CHUNK):
            s = slice(start, start + CHUNK)
            t = np.clip(((q[:, None, :] - a[None, s]) * d[None, s]).sum(axis=2) / length2[None, s],
                        0.0, 1.0)
            closest = a[None, s] + t[..., None] * d[None, s]
            gap = np.linalg.norm(q[:, None, :] - closest, axis=2)
            inside |= (gap <= self.radius + 1e-9).any(axis=1)
        held[near] = inside
        return held


def scallop_stepover(radius: float, scallop: float = SCALLOP) -> float:
    """Distance between neighbouring passes of a ball of `radius` leaving cusps `scallop`
    high on a flat."""
    return 2.0 * math.sqrt(max(radius ** 2 - (radius - scallop) ** 2, 0.0))


def finish_faces(part, directions: Sequence[np.ndarray], holes: Sequence = ()) -> list[int]:
    """Indices of the faces of `part` to finish with a ball: the curved ones, less the
    walls other passes finish: cylinders, cones and extrusions along a build direction
    (contour passes) and the walls of the holes filled and cut."""
    found = []
    for index, face in enumerate(part.Faces):
        surface = face.Surface
        kind = type(surface).__name__
        if plane_normal(face) is not None:
            continue                      # a plane, B-spline planes too: faced, not balled
        along = _generator(surface)
        if along is not None and any(abs(float(along @ d)) > PARALLEL
                                     for d in directions):
            continue
        if kind == "Cylinder" and any(hole.has_wall(surface) for hole in holes):
            continue
        found.append(index)
    return found


#: A face's straight generator lies along a direction when their cosine is past this.
PARALLEL = 1.0 - 1e-6


def _generator(surface) -> np.ndarray | None:
    """The direction of a cylinder's, cone's or extrusion's straight lines (None else)."""
    kind = type(surface).__name__
    if kind in ("Cylinder", "Cone"):
        v = surface.Axis
    elif kind == "SurfaceOfExtrusion":
        v = surface.Direction
    else:
        return None
    d = np.array([v.x, v.y, v.z])
    return d / np.linalg.norm(d)


def ball_passes(part, faces: Sequence[int], tool: MillTool, axes: Sequence[np.ndarray],
                points: np.ndarray, normals: np.ndarray, notes: list[str]) -> list[MillPass]:
    """Passes of the ball `tool` over the faces of `part` with these indices (`axes`: the
    build directions, the first the platform's normal; `points`, `normals`: samples of the
    part's surface)."""
    up = np.asarray(axes[0], dtype=float) / np.linalg.norm(axes[0])
    platform = float((points @ up).min())
    passes: list[MillPass] = []
    left_out = []
    for index in faces:
        face = part.Faces[index]
        grid = _grid(face, GRID, GRID)
        if grid is None:
            continue
        chosen = face_axes(grid[1][~np.isnan(grid[1][..., 0])], axes, up)
        if not chosen:
            left_out.append(f"Face{index + 1}")
            continue
        # spacings read on the surface and on the balls' centres: on a convex face the
        # centres spread wider than the points they touch, on a concave one narrower,
        # and the cusp between passes follows the wider
        centres = grid[0] + tool.radius * grid[1]
        lines = _lines(face, tool, np.concatenate([grid[0], centres], axis=2))
        for k, axis in enumerate(chosen):
            for line in lines:
                passes += _runs(line, axis, chosen[:k], tool, points, up, platform)
    if left_out:
        notes.append(f"ball finishing left out {', '.join(left_out)}: no tool axis from "
                     "above the platform has the ball's lower half on it")
    return passes


#: Tool axes a face is finished along, at most: a sphere takes one from above and three
#: level ones round its lower half.
MAX_AXES = 4

#: Normals of what is still unreached tried as axes (levelled where they point down).
PICKS = 16


def face_axes(normals: np.ndarray, axes: Sequence[np.ndarray], up: np.ndarray) -> list[np.ndarray]:
    """Tool axes that put the ball's lower half on the face's `normals` (k, 3), each
    chosen, of the build directions, the mean of the normals still unreached and some of
    them, to reach most of those, then to lean least from them; none from under the
    platform."""
    reach = math.cos(MAX_NORMAL_ANGLE) - 1e-9
    remaining = np.asarray(normals, dtype=float)
    chosen: list[np.ndarray] = []
    while len(remaining) and len(chosen) < MAX_AXES:
        # the mean of what is left, and a few of its normals, none from under the platform
        picks = remaining[np.linspace(0, len(remaining) - 1, min(len(remaining), PICKS)).astype(int)]
        candidates = [np.asarray(a, dtype=float) / np.linalg.norm(a) for a in axes]
        for v in [remaining.mean(axis=0), *picks]:
            v = v - min(0.0, float(v @ up)) * up
            if np.linalg.norm(v) > 1e-9:
                candidates.append(v / np.linalg.norm(v))
        candidates = [a for a in candidates if float(a @ up) >= -1e-9]

        def score(a: np.ndarray) -> tuple[int, float]:
            dots = remaining @ a
            return int((dots >= reach).sum()), float(dots.min())

        best = max(candidates, key=score) if candidates else None
        if best is None or score(best)[0] == 0:
            break
        chosen.append(best)
        remaining = remaining[remaining @ best < reach]
    return chosen


def _grid(face, nu: int, nv: int) -> tuple[np.ndarray, np.ndarray] | None:
    """(points, unit normals), each (nu, nv, 3) over the parameter range, NaN off the face."""
    u0, u1, v0, v1 = face.ParameterRange
    pts = np.full((nu, nv, 3), np.nan)
    normals = np.full((nu, nv, 3), np.nan)
    for i, u in enumerate(np.linspace(u0, u1, nu)):
        for j, v in enumerate(np.linspace(v0, v1, nv)):
            if not face.isPartOfDomain(u, v):
                continue
            pts[i, j] = tuple(face.valueAt(u, v))
            n = np.array(tuple(face.normalAt(u, v)))
            normals[i, j] = n / max(np.linalg.norm(n), 1e-12)
    if np.isnan(pts).all():
        return None
    return pts, normals


def _lines(face, tool: MillTool, grid: np.ndarray) -> list[list[tuple[np.ndarray, np.ndarray]]]:
    """Iso-parameter lines of the face, stepover apart, each a list of (point, normal) or
    None off the face, alternate lines reversed; passes run along the parameter with the
    longer lines. `grid`: (nu, nv, 6) surface points and the balls' centres."""
    u0, u1, v0, v1 = face.ParameterRange
    along_u = _spread(grid, axis=0)        # arc length along u, per v column
    along_v = _spread(grid, axis=1)
    if along_u >= along_v:       # lines run along u, one per v value
        lines_at, count_along = np.linspace(v0, v1, _count(along_v, tool)), _points(along_u)
        params = [[(u, v) for u in np.linspace(u0, u1, count_along)] for v in lines_at]
    else:
        lines_at, count_along = np.linspace(u0, u1, _count(along_u, tool)), _points(along_v)
        params = [[(u, v) for v in np.linspace(v0, v1, count_along)] for u in lines_at]
    lines = []
    for k, line in enumerate(params):
        points = []
        for u, v in (line if k % 2 == 0 else line[::-1]):
            if face.isPartOfDomain(u, v):
                normal = np.array(tuple(face.normalAt(u, v)))
                points.append((np.array(tuple(face.valueAt(u, v))),
                               normal / max(np.linalg.norm(normal), 1e-12)))
            else:
                points.append(None)
        lines.append(points)
    return lines


def _spread(grid: np.ndarray, axis: int) -> float:
    """The longest arc length (mm) of the grid's lines along one parameter, on the surface
    or on the balls' centres (grid (nu, nv, 6): both), whichever is longer."""
    steps = np.diff(grid, axis=axis)
    length = np.maximum(np.linalg.norm(steps[..., :3], axis=2), np.linalg.norm(steps[..., 3:], axis=2))
    return float(np.nan_to_num(length).sum(axis=axis).max(initial=0.0))


def _count(across: float, tool: MillTool) -> int:
    return max(2, math.ceil(across / scallop_stepover(tool.radius)) + 1)


def _points(length: float) -> int:
    return max(2, math.ceil(length / POINT_SPACING) + 1)


def _runs(line, axis: np.ndarray, earlier: Sequence[np.ndarray], tool: MillTool,
          samples: np.ndarray, up: np.ndarray, platform: float) -> list[MillPass]:
    """The line's stretches of ball positions along `axis` (those no `earlier` axis
    reaches) that reach nothing they must not: the part, the platform."""
    passes = []
    reach = math.cos(MAX_NORMAL_ANGLE) - 1e-9

    def mine(normal: np.ndarray) -> bool:
        return float(normal @ axis) >= reach and all(float(normal @ a) < reach for a in earlier)

    centres = [None if p is None or not mine(p[1]) else p[0] + tool.radius * p[1] for p in line]
    ok = [c is not None and float(c @ up) - tool.radius >= platform - GOUGE_SLACK
          for c in centres]
    known = [k for k, good in enumerate(ok) if good]
    if known:
        clear = _clear(np.array([centres[k] for k in known]), axis, tool, samples)
        for k, good in zip(known, clear):
            ok[k] = bool(good)
    run: list[np.ndarray] = []
    for k, good in enumerate(ok + [False]):
        if good:
            run.append(centres[k])
            continue
        if len(run) >= 2:
            c = np.array(run)
            passes.append(MillPass(c - tool.radius * axis, axis.copy(), "ball", tool, tool.feed,
                                   BallSweep(c, tool.radius)))
        run = []
    return passes


def _clear(centres: np.ndarray, axis: np.ndarray, tool: MillTool,
           samples: np.ndarray) -> np.ndarray:
    """(n,) whether a ball at each centre, its shank and holder, keep off the samples."""
    clear = np.ones(len(centres), dtype=bool)
    grip = tool.stick_out - tool.radius          # the holder's face, from the ball's centre
    reach = grip + tool.holder_length
    for start in range(0, len(centres), CHUNK):
        c = centres[start:start + CHUNK]
        rel = samples[None, :, :] - c[:, None, :]
        along = rel @ axis
        radial = np.linalg.norm(rel - along[..., None] * axis, axis=2)
        ball = np.linalg.norm(rel, axis=2) < tool.radius - GOUGE_SLACK
        shank = (along > 0) & (along <= grip) & (radial < tool.radius - GOUGE_SLACK)
        holder = ((along > grip) & (along <= reach)
                  & (radial < 0.5 * tool.holder_diameter))
        clear[start:start + CHUNK] = ~(ball | shank | holder).any(axis=1)
    return clear
