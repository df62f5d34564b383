"""Section loops: exact wires paired with their polygons in a 2D frame, outer loops and holes."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np
import shapely
from shapely.geometry import MultiPolygon, Polygon

from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry.frames import points_array
from freecad_conformal.tolerances import COINCIDENT_POINTS

#: Maps discretised 3D points (N, 3) of a loop to 2D coordinates (N, 2).
Mapping = Callable[[np.ndarray], np.ndarray]

#: How a section polygon without holes is repaired when its ring crosses itself: GEOS's
#: "structure" method keeps the area the ring encloses as one polygon, where "linework"
#: rebuilds it from every crossing (the sliced cylinder's 916 kinked sections, where a ruling
#: meets the slice face 0.00015 mm off: 0.28 s against 0.02 s, areas equal within 1e-14).
#: With holes it trusts the outer/hole labels, which `isSame` gets wrong on some Boolean
#: faces (two of the bottle's sections, a hole larger than its shell, came out empty):
#: those keep "linework".
RING_REPAIR = "structure"


def grid_key(geometry, step: float, origin: np.ndarray | None = None) -> bytes:
    """The 2D geometry's coordinates (less `origin`) in whole steps of `step`, as WKB: a
    dictionary key under which geometries the same but for rounding meet (+0.0: −0.0 has
    other bytes). A tenth of the time GEOS's set_precision takes."""
    shift = np.zeros(2) if origin is None else np.asarray(origin, dtype=float)
    return shapely.to_wkb(shapely.transform(
        geometry, lambda points: np.rint((points - shift) / step) + 0.0))


def following(values: np.ndarray) -> np.ndarray:
    """Each row's successor round a closed polygon: np.roll(values, -1, axis=0), which costs
    ten times as much for the short arrays of section loops."""
    return np.concatenate((values[1:], values[:1]))


def signed_area(points: np.ndarray) -> float:
    """Shoelace area of a closed polygon (first point not repeated); > 0 counter-clockwise."""
    x, y = points[:, 0], points[:, 1]
    return 0.5 * float(np.dot(x, following(y)) - np.dot(y, following(x)))


def dense_area(faces, frame, samples: int = 2001) -> float:
    """Area of planar section faces by the shoelace formula on their wires sampled densely
    in parameter (`samples` per edge): a check of OCC's area integration independent of it.
    A face's outer loop is taken as its largest (`isSame` misses on some Boolean faces)."""
    return dense_area_centroid(faces, frame, samples)[0]


def dense_area_centroid(faces, frame, samples: int = 2001) -> tuple[float, np.ndarray]:
    """`dense_area` and the faces' centroid in the frame's 2D coordinates, from the same
    densely sampled polygons (a check of OCC's moment integration too)."""
    total, moment = 0.0, np.zeros(2)
    for face in faces:
        rings = [frame.to_2d(_dense_points(wire, samples)) for wire in face.Wires]
        measured = sorted(((abs(signed_area(r)), _centroid(r)) for r in rings),
                          key=lambda item: -item[0])
        for index, (area, centroid) in enumerate(measured):
            sign = 1.0 if index == 0 else -1.0
            total += sign * area
            moment += sign * area * centroid
    return total, moment / total if total else moment


def _centroid(points: np.ndarray) -> np.ndarray:
    """Centroid of a closed polygon (first point not repeated), either orientation."""
    x, y = points[:, 0], points[:, 1]
    x1, y1 = np.roll(x, -1), np.roll(y, -1)
    cross = x * y1 - x1 * y
    area = 0.5 * cross.sum()
    return np.array([((x + x1) * cross).sum(), ((y + y1) * cross).sum()]) / (6.0 * area)


def _dense_points(wire, samples: int) -> np.ndarray:
    points = []
    for edge in wire.OrderedEdges:
        a, b = edge.ParameterRange
        run = [tuple(edge.valueAt(t)) for t in np.linspace(a, b, samples)]
        points.extend((run[::-1] if edge.Orientation == "Reversed" else run)[:-1])
    return np.array(points)


@dataclass
class Loop:
    """One closed boundary of a section face.

    `points` is the polygon in 2D coordinates at the stated chord tolerance, outer loops
    counter-clockwise and holes clockwise; `wire` is the exact 3D wire; `face_index` tells
    which section face (island) the loop bounds.
    """

    outer: bool
    points: np.ndarray
    wire: object = field(repr=False)
    face_index: int
    _exact_area: float | None = field(default=None, repr=False)

    @property
    def area(self) -> float:
        """Exact area enclosed by this loop alone (an OCC face built on its wire)."""
        if self._exact_area is None:
            _, Part = import_freecad()
            try:
                self._exact_area = float(Part.Face(self.wire).Area)
            except Part.OCCError:
                # A wire OCC cannot fill (non-planar loop on a cylinder, say): fall back to
                # the polygon, which is within the chord tolerance of the exact value.
                self._exact_area = abs(signed_area(self.points))
        return self._exact_area

    @property
    def polygon_area(self) -> float:
        return abs(signed_area(self.points))

    def to_dict(self, with_points: bool = True) -> dict:
        data = {"outer": self.outer, "area": self.area, "face": self.face_index}
        if with_points:
            data["points"] = np.round(self.points, 9).tolist()
        return data


def area_and_centroid(faces: list) -> tuple[float, np.ndarray]:
    """Exact total area of OCC faces and their area-weighted centroid (NaN when empty)."""
    area = float(sum(f.Area for f in faces))
    if not faces:
        return area, np.full(3, np.nan)
    moments = sum((np.array(tuple(f.CenterOfMass)) * f.Area for f in faces), np.zeros(3))
    return area, moments / area


def discretize_wire(wire, chord_tolerance: float) -> np.ndarray:
    """Points (N, 3) along the wire in its order, closing point dropped.

    Edge by edge: OCC's `Wire.discretize` ends the process (no exception) on a wire the
    Boolean returned open, a one-edge sliver of bottle.brep cut along +X (measured).
    """
    runs = []
    for edge in wire.OrderedEdges:
        run = points_array(edge.discretize(Deflection=chord_tolerance))
        if edge.Orientation == "Reversed":
            run = run[::-1]
        runs.append(run if not runs else run[1:])
    points = np.concatenate(runs) if runs else np.zeros((0, 3))
    if len(points) > 1 and np.linalg.norm(points[0] - points[-1]) < COINCIDENT_POINTS:
        points = points[:-1]
    return points


def loops_of_faces(faces: list, frame, chord_tolerance: float,
                   mapping: Mapping | None = None,
                   outer_first: Sequence[bool] | None = None) -> list[Loop]:
    """Loops of `faces` mapped to 2D by `frame.to_2d` (or `mapping`), oriented outer CCW.
    `outer_first`: per face, whether its first wire is known to be its outer one (else
    OCC's `OuterWire` tells, classifying the wires)."""
    to_2d = mapping if mapping is not None else frame.to_2d
    loops = []
    for index, face in enumerate(faces):
        first = outer_first is not None and outer_first[index]
        outer = None if first else face.OuterWire
        for place, wire in enumerate(face.Wires):
            is_outer = place == 0 if first else wire.isSame(outer)
            points = to_2d(discretize_wire(wire, chord_tolerance))
            if (signed_area(points) > 0) != is_outer:
                points = points[::-1].copy()
            loops.append(Loop(outer=is_outer, points=points, wire=wire, face_index=index))
    return loops


def loops_with_wires(faces: list, made: list[tuple[int, bool, np.ndarray]]) -> list[Loop] | None:
    """The loops `loops_of_faces` makes of `faces`, from their (face index, outer, points)
    made in that order by another process, each given its wire of `faces` back (a wire does
    not travel between processes). None when the counts of wires and loops differ."""
    wires = [wire for face in faces for wire in face.Wires]
    if len(wires) != len(made):
        return None
    return [Loop(outer=outer, points=points, wire=wire, face_index=index)
            for wire, (index, outer, points) in zip(wires, made)]


def polygons_of_loops(loops: list[Loop]) -> MultiPolygon:
    """Shapely polygons (one per island, holes inside) from loops grouped by face."""
    by_face: dict[int, dict] = {}
    for loop in loops:
        entry = by_face.setdefault(loop.face_index, {"shell": None, "holes": []})
        if loop.outer:
            entry["shell"] = loop.points
        else:
            entry["holes"].append(loop.points)
    polygons = []
    for entry in by_face.values():
        if entry["shell"] is None or len(entry["shell"]) < 3:
            continue
        polygon = Polygon(entry["shell"], [h for h in entry["holes"] if len(h) >= 3])
        if not polygon.is_valid:
            polygon = shapely.make_valid(polygon, method=RING_REPAIR if not polygon.interiors
                                         else "linework")
        polygons.extend(_polygons_in(polygon))
    return MultiPolygon(polygons)


def _polygons_in(geometry) -> list[Polygon]:
    if isinstance(geometry, Polygon):
        return [geometry] if not geometry.is_empty else []
    return [g for part in getattr(geometry, "geoms", []) for g in _polygons_in(part)]
