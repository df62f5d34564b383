"""Support volume a planar build needs: what stands under each overhanging face.

Each face (planar faces whole, curved faces by their mesh triangles) whose outward normal
points down by more than the overhang limit from the build direction is extruded down to
the platform; of that prism, less the part, the pieces that touch the face are the support
(a support stops on the part below it). This is the volume a slicer's "support everywhere"
fills densely; slicers print it sparse, so it is an upper bound on the material they use.
"""
from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry.frames import unit
from freecad_conformal.geometry.overhang import DEFAULT_OVERHANG_ANGLE, lowest_level

#: Mesh deflection (mm) for curved overhanging faces.
CURVED_DEFLECTION = 0.05

#: A support piece counts for a face when it is this close (mm) to it.
TOUCH = 1e-5


def support_volume(shape, direction: Sequence[float] = (0.0, 0.0, 1.0),
                   angle: float = DEFAULT_OVERHANG_ANGLE) -> float:
    """Support volume (mm³) under `shape` built along `direction` from its lowest level."""
    App, Part = import_freecad()
    d = unit(direction, "build direction")
    platform = lowest_level(shape, d)
    limit = -math.cos(angle)
    total = 0.0
    for face in shape.Faces:
        for piece in _overhanging(Part, App, face, d, limit):
            height = float(max(np.array(tuple(v.Point)) @ d for v in piece.Vertexes)) - platform
            if height <= TOUCH:
                continue
            prism = piece.extrude(App.Vector(*(-height * d)))
            for solid in prism.cut(shape).Solids:
                if solid.distToShape(piece)[0] <= TOUCH:
                    total += float(solid.Volume)
    return total


def _overhanging(Part, App, face, d: np.ndarray, limit: float) -> list:
    """The face itself (planar) or its mesh triangles that overhang."""
    if type(face.Surface).__name__ == "Plane":
        u0, u1, v0, v1 = face.ParameterRange
        normal = np.array(tuple(face.normalAt(0.5 * (u0 + u1), 0.5 * (v0 + v1))))
        return [face] if float(normal @ d) < limit else []
    points, triangles = face.tessellate(CURVED_DEFLECTION)
    pieces = []
    # Face.tessellate winds triangles with the face's orientation applied: their normals
    # point out of the solid (checked on a hole and a boss, tests/geometry/test_hybrid.py)
    for a, b, c in triangles:
        pa, pb, pc = (np.array(tuple(points[i])) for i in (a, b, c))
        normal = np.cross(pb - pa, pc - pa)
        size = float(np.linalg.norm(normal))
        if size < 1e-12:
            continue
        if float(normal @ d) / size < limit:
            wire = Part.makePolygon([points[a], points[b], points[c], points[a]])
            pieces.append(Part.Face(wire))
    return pieces
