"""Section faces on a plane from curve pieces: closed wires, outer loops and holes.

Pieces are chained at the crossing points they share (ids, not coordinates, so no tolerance
decides what joins). Each closed wire is oriented, ordered by the area it encloses and
nested from a polygon of it (`_Loop`), or, where the polygon's error could change that
decision, from OCC's exact integration of a face built on it alone; nesting depth tells
outer loops from holes. The faces' exact areas and centroids are integrated only when read
(`SectionFace`): layers and paths read the faces' loops, not their moments.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry.frames import points_array
from freecad_conformal.geometry.loops import following, signed_area
from freecad_conformal.tolerances import MIN_SECTION_AREA

#: A closed section loop enclosing less than this (mm²) is a sliver the Boolean would not
#: return either (it drops faces under it): leave it to the Boolean.
MIN_LOOP_AREA = MIN_SECTION_AREA

#: Chord deflection (mm) of the polygons that orient, order and nest a section's loops.
#: Sampling a wire at it costs a tenth of integrating its area (the bottle's 622 section
#: wires: 0.05 s against 0.21 s for the areas and 0.21 s more for the centroids).
LOOP_DEFLECTION = 1e-2

#: A polygon's area is trusted within this many times its perimeter × LOOP_DEFLECTION of
#: the exact one (the area between an arc and its chord is at most chord × sagitta; the
#: factor covers OCC checking the deflection at samples only), and a point this many
#: deflections from it is on the side of the exact loop the polygon says.
POLYGON_ERROR_FACTOR = 4.0

#: (edges, first crossing id, last crossing id); ids are None for a whole closed curve.
Piece = tuple[list, "int | None", "int | None"]


class SectionFace(NamedTuple):
    """One section face. `outer_first`: its first wire is its outer one, as in the faces
    built here (a Boolean's faces are asked: OCC classifies each wire for that, 0.7 ms a
    face of the bottle). Its area and centroid are OCC's integrals, made at each read (a
    section reads them once, when asked: `sections.PlanarSection.area`)."""

    face: object
    outer_first: bool = False

    @property
    def area(self) -> float:
        return float(self.face.Area)

    @property
    def centroid(self) -> np.ndarray:
        return np.array(tuple(self.face.CenterOfMass))


def faces_from_pieces(pieces: list[Piece], point_count: int, plane) -> list[SectionFace] | None:
    """Faces bounded by the pieces, or None unless every crossing joins exactly two pieces
    into closed wires."""
    degree = np.zeros(point_count, dtype=int)
    for _, first, last in pieces:
        for pid in (first, last):
            if pid is not None:
                degree[pid] += 1
    if np.any((degree != 0) & (degree != 2)):
        return None
    wires = _chain(pieces)
    if wires is None:
        return None
    return _faces_of_wires(wires, plane)


def _chain(pieces: list[Piece]) -> list | None:
    """Closed wires from pieces joined at their crossing ids."""
    _, Part = import_freecad()
    at_point: dict[int, list[int]] = {}
    for index, (_, first, last) in enumerate(pieces):
        for pid in (first, last):
            if pid is not None:
                at_point.setdefault(pid, []).append(index)
    used = [False] * len(pieces)
    wires = []
    for index, (edges, first, last) in enumerate(pieces):
        if used[index]:
            continue
        used[index] = True
        chain, current = list(edges), last
        while current is not None and current != first:
            following = [i for i in at_point[current] if not used[i]]
            if not following:
                return None
            used[following[0]] = True
            more, a, b = pieces[following[0]]
            # A piece of several edges walked from its far end joins edge by edge backwards.
            chain.extend(more if a == current else more[::-1])
            current = b if a == current else a
        try:
            wire = Part.Wire(chain)
        except Part.OCCError:
            return None
        if not wire.isClosed():
            return None
        wires.append(wire)
    return wires


def _faces_of_wires(wires: list, plane) -> list[SectionFace] | None:
    """Faces on `plane` from closed wires: nesting depth decides outer loops and holes.

    A face built on the plane with one wire added (no orientation check, which would
    classify the infinite point) has a negative area when the wire turns clockwise about
    the normal; that sign orients every wire, the areas order them (largest first: an
    enclosing loop comes before what it encloses) and only wires whose boxes nest need a
    containment test. Each of these is read from the wire's polygon where its error cannot
    change the answer, else from the exact face (`_Loop`): the same faces, in the same
    order, as from exact areas alone.
    """
    _, Part = import_freecad()
    frame = PlaneFrame(plane)
    loops = [_Loop(wire, plane, frame) for wire in wires]
    if any(loop.sliver() for loop in loops):
        return None
    loops = _largest_first(loops)
    parent: list[int | None] = []
    for i, loop in enumerate(loops):
        container = None
        for j in range(i - 1, -1, -1):   # the smallest enclosing loop comes last
            if loops[j].holds(loop):
                container = j
                break
        parent.append(container)
    faces = []
    for i, loop in enumerate(loops):
        if _depth(parent, i) % 2:
            continue
        holes = [loops[k] for k in range(len(loops)) if parent[k] == i]
        if _no_net_area(loop, holes):
            return None
        face = Part.Face(plane, [loop.oriented()] + [hole.oriented().reversed() for hole in holes])
        faces.append(SectionFace(face, outer_first=True))
    return faces


class PlaneFrame:
    """2D coordinates in a Part.Plane: x, y along its axes (x × y its normal, so a positive
    polygon area is the positive exact one)."""

    def __init__(self, plane) -> None:
        App, _ = import_freecad()
        self.origin = np.array(tuple(plane.Position))
        self.x_axis = np.array(tuple(plane.Rotation.multVec(App.Vector(1, 0, 0))))
        self.y_axis = np.array(tuple(plane.Rotation.multVec(App.Vector(0, 1, 0))))
        self.axes = np.array([self.x_axis, self.y_axis]).T

    def to_2d(self, points: np.ndarray) -> np.ndarray:
        return (points - self.origin) @ self.axes


class _Loop:
    """One closed wire with its polygon at LOOP_DEFLECTION: the signed area, box and
    containment read from the polygon within a stated error (`error`, mm²; `margin`, mm),
    and from the exact face built on the wire alone (computed once, when needed) where
    that error could change the answer."""

    def __init__(self, wire, plane, frame: PlaneFrame) -> None:
        self.wire, self._plane = wire, plane
        points = points_array(wire.discretize(Deflection=LOOP_DEFLECTION))
        self.polygon = frame.to_2d(points)
        self._frame = frame
        self.polygon_area = signed_area(self.polygon)
        perimeter = float(np.linalg.norm(np.diff(self.polygon, axis=0, append=self.polygon[:1]),
                                         axis=1).sum())
        self.margin = POLYGON_ERROR_FACTOR * LOOP_DEFLECTION
        self.error = perimeter * self.margin
        self.low, self.high = self.polygon.min(axis=0), self.polygon.max(axis=0)
        self._exact: float | None = None
        self._probe: np.ndarray | None = None

    def exact_area(self) -> float:
        """The signed area of the face on the plane with this wire alone (OCC's integral)."""
        if self._exact is None:
            _, Part = import_freecad()
            self._exact = float(Part.Face(self._plane, [self.wire]).Area)
        return self._exact

    def _trusted(self) -> bool:
        return abs(self.polygon_area) > self.error + MIN_LOOP_AREA and self._exact is None

    def signed_area(self) -> float:
        """The polygon's signed area where it decides the sign and is no sliver, else the
        exact one."""
        return self.polygon_area if self._trusted() else self.exact_area()

    def bounds(self) -> tuple[float, float]:
        """Where the exact enclosed area lies (mm²)."""
        if self._trusted():
            size = abs(self.polygon_area)
            return size - self.error, size + self.error
        size = abs(self.exact_area())
        return size, size

    def sliver(self) -> bool:
        return abs(self.signed_area()) <= MIN_LOOP_AREA

    def oriented(self):
        """The wire turning counter-clockwise about the plane's normal."""
        return self.wire if self.signed_area() > 0 else self.wire.reversed()

    def probe(self) -> np.ndarray:
        """A point of the exact wire: the middle of its first edge."""
        if self._probe is None:
            edge = self.wire.Edges[0]
            self._probe = np.array(tuple(edge.valueAt(
                0.5 * (edge.FirstParameter + edge.LastParameter))))
        return self._probe

    def holds(self, inner: "_Loop") -> bool:
        """Whether `inner` lies inside this loop (loops of one section do not cross)."""
        slack = self.margin
        if np.any(inner.low < self.low - slack) or np.any(inner.high > self.high + slack):
            return False
        probe = inner.probe()
        point = self._frame.to_2d(probe[None, :])[0]
        if _distance_to_polygon(point, self.polygon) > self.margin:
            return _inside_polygon(point, self.polygon)
        # Near the polygon: ask OCC, on the face the loop encloses (its wire turning
        # counter-clockwise; one turning the other way would make a face of all but it).
        App, Part = import_freecad()
        return bool(Part.Face(self._plane, [self.oriented()]).isInside(App.Vector(*probe), 1e-9,
                                                                         True))


def _largest_first(loops: list[_Loop]) -> list[_Loop]:
    """`loops` by exact enclosed area, largest first, ties in their given order: the polygon
    areas order loops whose error bounds are apart; those that overlap are integrated."""
    order = sorted(range(len(loops)), key=lambda i: -abs(loops[i].polygon_area))
    bounds = [loops[i].bounds() for i in order]
    # highest[p]: the largest area any loop from place p on may have
    highest = np.maximum.accumulate([high for _, high in bounds][::-1])[::-1]
    result: list[int] = []
    group: list[int] = []
    lowest = math.inf
    for place, index in enumerate(order):
        if group and lowest > highest[place]:
            result.extend(_exactly_ordered(group, loops))
            group, lowest = [], math.inf
        group.append(index)
        lowest = min(lowest, bounds[place][0])
    result.extend(_exactly_ordered(group, loops))
    return [loops[i] for i in result]


def _exactly_ordered(group: list[int], loops: list[_Loop]) -> list[int]:
    if len(group) < 2:
        return group
    return sorted(group, key=lambda i: (-abs(loops[i].exact_area()), i))


def _no_net_area(outer: _Loop, holes: list[_Loop]) -> bool:
    """Whether the face of `outer` less its holes encloses no more than MIN_LOOP_AREA."""
    low = outer.bounds()[0] - sum(hole.bounds()[1] for hole in holes)
    if low > MIN_LOOP_AREA:
        return False
    net = abs(outer.exact_area()) - sum(abs(hole.exact_area()) for hole in holes)
    return net <= MIN_LOOP_AREA


def _depth(parent: list[int | None], index: int) -> int:
    depth, above = 0, parent[index]
    while above is not None:
        depth, above = depth + 1, parent[above]
    return depth


def _inside_polygon(point: np.ndarray, polygon: np.ndarray) -> bool:
    """Even-odd test of a point against a closed polygon (its last point joins its first)."""
    x, y = polygon[:, 0], polygon[:, 1]
    x1, y1 = following(x), following(y)
    crossing = (y > point[1]) != (y1 > point[1])
    if not crossing.any():
        return False
    xa, ya, xb, yb = x[crossing], y[crossing], x1[crossing], y1[crossing]
    at = xa + (point[1] - ya) * (xb - xa) / (yb - ya)
    return bool(np.count_nonzero(point[0] < at) % 2)


def _distance_to_polygon(point: np.ndarray, polygon: np.ndarray) -> float:
    """Distance (mm) from a point to a closed polygon's edges."""
    start = polygon
    step = following(polygon) - start
    length2 = np.einsum("ij,ij->i", step, step)
    t = np.einsum("ij,ij->i", point - start, step) / np.maximum(length2, 1e-300)
    nearest = start + np.minimum(np.maximum(t, 0.0), 1.0)[:, None] * step
    return float(np.sqrt(np.min(np.einsum("ij,ij->i", nearest - point, nearest - point))))
