"""Round holes of a solid, and the solid with chosen holes filled (hybrid plans).

A hybrid plan deposits over holes it cannot build (too small for the bead, or across the
build direction, where their ceiling would overhang) and machines them out afterwards
(METHODS section 6). A hole is the set of concave cylindrical faces about one axis with
one radius that together go all the way round (STEP files often split a hole into two
half cylinders); its extent along the axis comes from the faces' vertices and bounding
boxes. Fillets (concave but partial) and bosses (convex) are not holes.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from freecad_conformal.errors import GeometryError
from freecad_conformal.freecad_env import import_freecad

#: Two cylinders are the same hole when their axes and radii agree to this (mm): STEP
#: writers repeat a hole's axis and radius to about 1e-7.
SAME_HOLE = 1e-4

#: The faces of a hole must cover the full turn to this (rad): a half cylinder is π.
FULL_TURN_SLACK = 1e-3

#: Filling cylinders are made this much wider (mm) than the hole, so that the fused solid
#: has no sliver faces where the filler touches the hole's wall.
FILL_OVERLAP = 1e-3


@dataclass(frozen=True)
class Hole:
    """A round hole: its axis (a point and a unit direction), radius and the span of its
    faces along the axis (`low`, `high`, from the point); `through` when both ends open
    onto the outside (neither end is closed by a face of the solid)."""

    point: np.ndarray
    direction: np.ndarray
    radius: float
    low: float
    high: float
    open_ends: tuple[str, ...]

    @property
    def through(self) -> bool:
        return len(self.open_ends) == 2

    @property
    def diameter(self) -> float:
        return 2.0 * self.radius

    @property
    def length(self) -> float:
        return self.high - self.low

    def end(self, which: str) -> np.ndarray:
        """The axis point at the hole's 'low' or 'high' end."""
        return self.point + (self.low if which == "low" else self.high) * self.direction

    def has_wall(self, cylinder) -> bool:
        """Whether a cylindrical surface lies on this hole's line with its radius (the
        test `find_holes` groups a hole's faces by)."""
        axis = np.array(tuple(cylinder.Axis), dtype=float)
        return _key(np.array(tuple(cylinder.Center), dtype=float), axis / np.linalg.norm(axis),
                    float(cylinder.Radius)) == _key(self.point, self.direction, self.radius)

    def across(self, build_direction: np.ndarray, limit: float) -> bool:
        """True when the axis leans more than `limit` (rad) from the build direction."""
        cosine = abs(float(np.dot(self.direction, build_direction)))
        return math.acos(min(1.0, cosine)) > limit


def find_holes(solid) -> list[Hole]:
    """The round holes of `solid` (see the module docstring), largest first."""
    groups: dict[tuple, list] = {}
    for face in solid.Faces:
        surface = face.Surface
        if type(surface).__name__ != "Cylinder":
            continue
        axis = np.array(tuple(surface.Axis), dtype=float)
        axis /= np.linalg.norm(axis)
        centre = np.array(tuple(surface.Center), dtype=float)
        if not _concave(face, centre, axis):
            continue
        key = _key(centre, axis, float(surface.Radius))
        groups.setdefault(key, []).append((face, centre, axis, float(surface.Radius)))
    holes = [hole for faces in groups.values() if (hole := _hole(solid, faces)) is not None]
    return sorted(holes, key=lambda h: -h.radius)


def _key(centre: np.ndarray, axis: np.ndarray, radius: float) -> tuple:
    """A hashable name for the line and radius (axis sign and the point along it removed)."""
    if axis[np.argmax(np.abs(axis))] < 0:
        axis = -axis
    foot = centre - (centre @ axis) * axis
    quantum = SAME_HOLE
    return tuple(np.round(np.concatenate((axis, foot, [radius])) / quantum).astype(np.int64))


def _concave(face, centre: np.ndarray, axis: np.ndarray) -> bool:
    """A face whose material lies outside its cylinder: its outward normal points at the axis."""
    u0, u1, v0, v1 = face.ParameterRange
    point = face.valueAt(0.5 * (u0 + u1), 0.5 * (v0 + v1))
    normal = face.normalAt(0.5 * (u0 + u1), 0.5 * (v0 + v1))
    p = np.array(tuple(point), dtype=float)
    radial = (p - centre) - ((p - centre) @ axis) * axis
    return float(np.dot(np.array(tuple(normal)), radial)) < 0.0


def _hole(solid, faces: list) -> Hole | None:
    turn = sum(face.ParameterRange[1] - face.ParameterRange[0] for face, *_ in faces)
    if turn < 2.0 * math.pi - FULL_TURN_SLACK:
        return None                      # a concave fillet or a partial groove
    _, centre, axis, radius = faces[0]
    heights = [float((np.array(tuple(v.Point)) - centre) @ axis)
               for face, *_ in faces for v in face.Vertexes]
    if not heights:                      # a seamless cylinder: its box gives the span
        raise GeometryError(f"hole of radius {radius:g} mm at {np.round(centre, 3).tolist()} "
                            "has no vertices to measure its length")
    low, high = min(heights), max(heights)
    open_ends = tuple(name for name, h, sign in (("low", low, -1.0), ("high", high, 1.0))
                      if _open_end(solid, centre + h * axis, axis * sign, radius))
    return Hole(centre, axis, radius, low, high, open_ends)


def _open_end(solid, point: np.ndarray, outward: np.ndarray, radius: float) -> bool:
    """True when just past the hole's end, on its axis, there is no material."""
    App, _ = import_freecad()
    probe = point + outward * min(0.5 * radius, 0.05)
    return not solid.isInside(App.Vector(*probe), 1e-6, True)


def filled(solid, holes: list[Hole]):
    """`solid` with `holes` filled by cylinders (one fused, refined solid)."""
    if not holes:
        return solid
    App, Part = import_freecad()
    fillers = []
    for hole in holes:
        base = hole.end("low")
        fillers.append(Part.makeCylinder(hole.radius + FILL_OVERLAP, hole.length,
                                         App.Vector(*base), App.Vector(*hole.direction)))
    result = solid.fuse(fillers).removeSplitter()
    solids = result.Solids
    if len(solids) != 1:
        raise GeometryError(f"filling {len(holes)} hole(s) gave {len(solids)} solids, not one")
    return solids[0]
