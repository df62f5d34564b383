"""Exact cylindrical sections: a solid cut by coaxial cylinders (builds on a rotating mandrel).

Each section is the Boolean common of the solid with the lateral face of a cylinder of the
given radius, so its faces lie exactly on that cylinder and their OCC areas are exact. Loops
are returned as exact 3D wires and unrolled into the plane (s, a): s the arc length at that
radius measured from the frame's u axis, a the axial position. A cylinder is developable, so
areas in the unrolled plane equal areas on the cylinder.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

from freecad_conformal.errors import GeometryError
from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry.frames import LayerFrame
from freecad_conformal.geometry.loops import (Loop, area_and_centroid, loops_of_faces,
                                               polygons_of_loops, signed_area)
from freecad_conformal.geometry.solids import solids_of
from freecad_conformal.tolerances import DEFAULT_CHORD_TOLERANCE, MIN_SECTION_AREA


@dataclass(frozen=True)
class CylinderAxis:
    """A cylinder axis through `point` along unit `frame.n`; angles measured from `frame.u`."""

    point: np.ndarray
    frame: LayerFrame

    @classmethod
    def make(cls, point: Sequence[float], direction: Sequence[float]) -> "CylinderAxis":
        origin = np.asarray(point, dtype=float).reshape(-1)
        if origin.shape != (3,) or not np.all(np.isfinite(origin)):
            raise GeometryError(f"axis point must be three finite numbers, got {list(point)!r}")
        return cls(point=origin, frame=LayerFrame.for_direction(direction))

    def unroll(self, points: np.ndarray, radius: float) -> np.ndarray:
        """Points (N, 3) on the cylinder -> (arc length, axial) (N, 2), angle unwrapped."""
        w = np.asarray(points, dtype=float) - self.point
        axial = w @ self.frame.n
        angle = np.unwrap(np.arctan2(w @ self.frame.v, w @ self.frame.u))
        return np.column_stack((radius * angle, axial))

    def roll(self, unrolled: np.ndarray, radius: float) -> np.ndarray:
        """(arc length, axial) (N, 2) -> points (N, 3) on the cylinder of `radius`."""
        s, a = np.asarray(unrolled, dtype=float).T
        angle = s / radius
        return (self.point + np.outer(a, self.frame.n)
                + radius * (np.outer(np.cos(angle), self.frame.u) + np.outer(np.sin(angle), self.frame.v)))


@dataclass
class CylindricalSection:
    radius: float
    axis: CylinderAxis
    faces: list = field(repr=False)
    area: float
    centroid: np.ndarray
    chord_tolerance: float = DEFAULT_CHORD_TOLERANCE
    _loops: list[Loop] | None = field(default=None, repr=False)

    @property
    def is_empty(self) -> bool:
        return not self.faces

    @property
    def loops(self) -> list[Loop]:
        """Loops in the unrolled plane (outer counter-clockwise, holes clockwise)."""
        if self._loops is None:
            loops = loops_of_faces(self.faces, self.axis.frame, self.chord_tolerance,
                                   mapping=lambda pts: self.axis.unroll(pts, self.radius))
            for loop in loops:
                # Developable surface: the unrolled polygon area is the area on the cylinder.
                loop._exact_area = abs(signed_area(loop.points))
            self._loops = loops
        return self._loops

    def polygons(self):
        return polygons_of_loops(self.loops)

    def to_dict(self, with_points: bool = True) -> dict:
        return {
            "radius": self.radius,
            "area": self.area,
            "centroid": [float(c) for c in self.centroid],
            "loops": [loop.to_dict(with_points) for loop in self.loops],
        }


class CylindricalSlicer:
    """Cuts the solids of one shape with cylinders coaxial to one axis."""

    def __init__(self, shape, point: Sequence[float] = (0, 0, 0),
                 direction: Sequence[float] = (0, 0, 1),
                 chord_tolerance: float = DEFAULT_CHORD_TOLERANCE) -> None:
        self._App, self._Part = import_freecad()
        if not np.isfinite(chord_tolerance) or chord_tolerance <= 0:
            raise GeometryError(f"chord tolerance must be a positive length, got {chord_tolerance!r}")
        self.solids = solids_of(shape)
        self.axis = CylinderAxis.make(point, direction)
        self.chord_tolerance = chord_tolerance

    def _cut(self, solid, radius: float, seam_angle: float) -> list:
        App, Part = self._App, self._Part
        box = solid.BoundBox
        reach = box.DiagonalLength + float(np.linalg.norm(
            np.array([box.Center.x, box.Center.y, box.Center.z]) - self.axis.point)) + 1.0
        base = self.axis.point - reach * self.axis.frame.n
        cylinder = Part.makeCylinder(radius, 2 * reach, App.Vector(*base),
                                     App.Vector(*self.axis.frame.n))
        lateral = [f for f in cylinder.Faces if f.Surface.__class__.__name__ == "Cylinder"][0]
        seam = [e for e in lateral.Edges if e.Curve.__class__.__name__ in ("Line", "LineSegment")][0]
        w = np.array(tuple(seam.Vertexes[0].Point)) - self.axis.point
        current = float(np.arctan2(w @ self.axis.frame.v, w @ self.axis.frame.u))
        lateral.rotate(App.Vector(*base), App.Vector(*self.axis.frame.n),
                       float(np.degrees(seam_angle - current)))
        return [f for f in solid.common(lateral).Faces if f.Area > MIN_SECTION_AREA]

    def section(self, radius: float) -> CylindricalSection:
        if not np.isfinite(radius) or radius <= 0:
            raise GeometryError(f"cylinder radius must be a positive length, got {radius!r}")
        faces = []
        for solid in self.solids:
            cut = self._cut(solid, radius, seam_angle=0.0)
            gap = _largest_angular_gap(cut, self.axis)
            if gap is not None and cut:
                # Put the cylinder's seam where there is no material, so no island is split
                # in two at the seam (one loop per island in the unrolled plane).
                cut = self._cut(solid, radius, seam_angle=gap)
            faces.extend(cut)
        area, centroid = area_and_centroid(faces)
        return CylindricalSection(radius=float(radius), axis=self.axis, faces=faces, area=area,
                                  centroid=centroid, chord_tolerance=self.chord_tolerance)


def _largest_angular_gap(faces: list, axis: CylinderAxis) -> float | None:
    """Middle angle of the widest angular gap free of the faces' vertices and edge samples,
    or None when the material goes all the way round (or there is none)."""
    samples = []
    for face in faces:
        for edge in face.Edges:
            samples.extend(tuple(p) for p in edge.discretize(16))
    if not samples:
        return None
    w = np.array(samples) - axis.point
    angles = np.sort(np.mod(np.arctan2(w @ axis.frame.v, w @ axis.frame.u), 2 * np.pi))
    gaps = np.diff(np.concatenate((angles, [angles[0] + 2 * np.pi])))
    widest = int(np.argmax(gaps))
    if gaps[widest] < 1e-6:
        return None
    return float(angles[widest] + gaps[widest] / 2)


@dataclass
class CylindricalStack:
    axis: CylinderAxis
    layers: list[CylindricalSection]
    chord_tolerance: float

    def to_dict(self, with_points: bool = True) -> dict:
        frame = self.axis.frame
        return {
            "format": "conformal.sections/1",
            "kind": "cylindrical",
            "direction": [float(c) for c in frame.n],
            "axis_point": [float(c) for c in self.axis.point],
            "angle_zero": [float(c) for c in frame.u],
            "chord_tolerance": self.chord_tolerance,
            "layers": [{"height": layer.radius, **layer.to_dict(with_points)} for layer in self.layers],
        }


def cylindrical_sections(shape, radii: Sequence[float], point: Sequence[float] = (0, 0, 0),
                         direction: Sequence[float] = (0, 0, 1), *,
                         chord_tolerance: float = DEFAULT_CHORD_TOLERANCE,
                         progress: Callable[[int, int], None] | None = None) -> CylindricalStack:
    """Sections of `shape` by coaxial cylinders of the given radii about (point, direction)."""
    slicer = CylindricalSlicer(shape, point, direction, chord_tolerance)
    radii = [float(r) for r in radii]
    if not radii:
        raise GeometryError("give at least one cylinder radius")
    layers = []
    for index, radius in enumerate(radii):
        layers.append(slicer.section(radius))
        if progress is not None:
            progress(index + 1, len(radii))
    return CylindricalStack(axis=slicer.axis, layers=layers, chord_tolerance=chord_tolerance)
