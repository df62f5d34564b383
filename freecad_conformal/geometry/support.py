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
from freecad_conformal.tolerances import ROUNDING_SLACK

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


#: Surface samples for the support under 3-D layers: mesh triangles split until no edge is
#: longer than this (mm), each classified by the layer its centre lies in.
LAYERED_SAMPLE = 1.0

#: Rays start this far (mm) off the surface, so they do not hit their own triangle.
RAY_START = 1e-4


def layered_support_volume(shape, direction: Sequence[float], layers: Sequence | None = None,
                           angle: float = DEFAULT_OVERHANG_ANGLE) -> float:
    """Support volume (mm³) under `shape` built from the platform normal to `direction`
    in `layers` (layers/model.Layer, possibly 3-D; None: planar along `direction`): a
    surface point overhangs when its normal points down by more than the overhang limit
    from the normal of the layer it lies in, and its support is the column along that
    normal down to the first surface of the part below it or the platform. Sampled
    (`LAYERED_SAMPLE`). Unlike `support_volume` a column stops at the first surface it
    meets, so a part's overhang above another is not counted twice (a branch leaning over
    its block: 22,482 mm³ where `support_volume` gives 25,912); on parts without that they
    agree to 0.1 % (tests/geometry/test_hybrid_groups.py)."""
    from freecad_conformal.geometry.surface_mesh import surface_mesh

    mesh = surface_mesh(shape)
    if mesh is None:
        return support_volume(shape, direction, angle)
    b = unit(direction, "build direction")
    platform = lowest_level(shape, b)
    corners = mesh.points[mesh.triangles]                      # (M, 3, 3)
    small = _split(corners, LAYERED_SAMPLE)
    centres = small.mean(axis=1)
    cross = np.cross(small[:, 1] - small[:, 0], small[:, 2] - small[:, 0])
    areas = 0.5 * np.linalg.norm(cross, axis=1)
    keep = areas > 1e-12
    small, centres, cross, areas = small[keep], centres[keep], cross[keep], areas[keep]
    normals = cross / (2.0 * areas[:, None])
    local = (_layer_normals(centres, layers) if layers
             else np.broadcast_to(b, centres.shape).copy())
    facing = np.einsum("ij,ij->i", normals, local)
    # a face exactly at the limit (a branch leaning 45°) prints without support
    over = facing < -math.cos(angle) - ROUNDING_SLACK
    if not over.any():
        return 0.0
    starts = centres[over] - RAY_START * local[over]
    down = -local[over]
    rise = local[over] @ b
    with np.errstate(divide="ignore"):
        # a column leaning away from the platform reaches it never, only the part
        to_platform = np.where(rise > 1e-9, (starts @ b - platform) / rise, np.inf)
    hits = _first_hits(starts, down, corners)
    height = np.minimum(np.maximum(to_platform, 0.0), hits)
    height = np.where(np.isfinite(height), height, 0.0)
    return float(np.sum(areas[over] * -facing[over] * height))


def _split(triangles: np.ndarray, longest: float) -> np.ndarray:
    """Triangles (K, 3, 3) split four ways until no edge is longer than `longest`."""
    done = []
    while len(triangles):
        edges = np.linalg.norm(triangles - np.roll(triangles, 1, axis=1), axis=2).max(axis=1)
        fine = edges <= longest
        done.append(triangles[fine])
        t = triangles[~fine]
        a, b, c = t[:, 0], t[:, 1], t[:, 2]
        ab, bc, ca = 0.5 * (a + b), 0.5 * (b + c), 0.5 * (c + a)
        triangles = np.concatenate([np.stack(s, axis=1) for s in
                                    ((a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca))])
    return np.concatenate(done) if done else np.zeros((0, 3, 3))


def _layer_normals(points: np.ndarray, layers: Sequence) -> np.ndarray:
    """Per point, the top normal of the first layer whose top plane is not below it (the
    last layer's above the stack)."""
    tops = np.array([np.asarray(layer.top_point, dtype=float) for layer in layers])
    normals = np.array([np.asarray(layer.top_normal, dtype=float) for layer in layers])
    # (P, L): how far each point lies above each layer's top plane
    above = np.einsum("pk,lk->pl", points, normals) - np.einsum("lk,lk->l", tops, normals)
    inside = above <= 1e-9
    index = np.where(inside.any(axis=1), inside.argmax(axis=1), len(layers) - 1)
    return normals[index]


def _first_hits(starts: np.ndarray, directions: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Distance along each ray to the first triangle it crosses (inf if none): the rays of
    one direction at a time, against the triangles binned across it (`RayGrid`)."""
    from freecad_conformal.geometry.inside import RayGrid, first_hits_below

    out = np.full(len(starts), np.inf)
    if not len(starts) or not len(triangles):
        return out
    kinds, which = np.unique(np.round(directions, 12), axis=0, return_inverse=True)
    for k, direction in enumerate(kinds):
        rays = np.flatnonzero(which.reshape(-1) == k)
        # the rays run down the grid's axis: the grid stands along their reverse
        out[rays] = first_hits_below(RayGrid(triangles, -direction), starts[rays])
    return out
