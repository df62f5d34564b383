"""Concave edges of a solid: where two faces meet at an inner angle over 180°.

The angle is measured inside the material from OCC's outward normals at points along the
edge: with n1, n2 the normals of the two faces and b1 the direction that leaves the edge
into face 1 (tangent to it, perpendicular to the edge), the edge is concave when b1·n2 > 0
(face 2 turns towards face 1's side of the material), convex when b1·n2 < 0, smooth when
the normals agree.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry.boxes import optimal_box
from freecad_conformal.geometry.shape_cache import ShapeCache
from freecad_conformal.geometry.shape_access import hash_code, is_same

#: Faces meeting with normals closer than this (rad) are tangent (fillet runs, seams): 0.5°
#: is above the normal noise of B-spline fits and below any deliberate corner.
SMOOTH_ANGLE = math.radians(0.5)

#: Fractions along the edge where normals are read: three points, ends avoided (vertices
#: are where other faces join and normals are ill defined).
SAMPLE_FRACTIONS = (0.25, 0.5, 0.75)

#: Step (mm, relative to the edge length) taken off the edge to tell which side a face lies.
PROBE_FRACTION = 1e-3

#: An edge's curve on a face whose parameter range matches the edge's to this share is
#: taken to share its parametrisation (OCC's SameParameter edges: the same t, the same
#: point), so its (u, v) need no projection.
SAME_PARAMETER = 1e-9


@dataclass(frozen=True)
class EdgeAngle:
    """One edge shared by two faces (indices into solid.Faces) and its inner angle (rad)."""

    edge_index: int
    faces: tuple[int, int]
    inner_angle: float
    edge: object

    @property
    def concave(self) -> bool:
        return self.inner_angle > math.pi + SMOOTH_ANGLE

    def to_dict(self) -> dict:
        return {"edge": f"Edge{self.edge_index + 1}",
                "faces": [f"Face{i + 1}" for i in self.faces],
                "inner_angle_deg": math.degrees(self.inner_angle), "concave": self.concave}


def _vec(v) -> np.ndarray:
    return np.array([v.x, v.y, v.z])


def _normals_along(face, edge, parameters: list[float], points: list) -> list[np.ndarray]:
    """The face's outward normals at the edge's `points` (at edge `parameters`): their
    (u, v) read off the edge's curve on the face where it shares the edge's parametrisation
    (OCC's same-parameter edges), else projected. Projecting onto a B-spline surface cost
    CrankArm's concave-edge scan a third of its 0.66 s."""
    found = face.curveOnSurface(edge)
    first, last = edge.ParameterRange
    if (found is not None and abs(found[1] - first) <= SAME_PARAMETER * max(1.0, abs(first))
            and abs(found[2] - last) <= SAME_PARAMETER * max(1.0, abs(last))):
        on_face = [found[0].value(t) for t in parameters]
        uv = [(p.x, p.y) for p in on_face]
    else:
        uv = [face.Surface.parameter(point) for point in points]
    return [_vec(face.normalAt(u, v)) for u, v in uv]


def into_face(face, point: np.ndarray, tangent: np.ndarray, normal: np.ndarray,
               probe: float) -> np.ndarray:
    """Unit direction leaving the edge point into `face`, tangent to it."""
    App, Part = import_freecad()
    side = np.cross(normal, tangent)
    side /= np.linalg.norm(side)
    surface = face.Surface
    ahead = face.isPartOfDomain(*surface.parameter(App.Vector(*(point + probe * side))))
    behind = face.isPartOfDomain(*surface.parameter(App.Vector(*(point - probe * side))))
    if ahead != behind:
        return side if ahead else -side
    # Both or neither in the domain (a probe across a seam or a pinched corner): ask the
    # exact distance instead, slower but unambiguous.
    inside = face.distToShape(Part.Vertex(App.Vector(*(point + probe * side))))[0]
    outside = face.distToShape(Part.Vertex(App.Vector(*(point - probe * side))))[0]
    return side if inside <= outside else -side


def edge_angles(solid, only=None) -> list[EdgeAngle]:
    """Inner angle of every edge shared by exactly two faces of `solid` (seams skipped);
    with `only`, of the edges for which `only(edge)` is true."""
    App, Part = import_freecad()
    faces = list(solid.Faces)
    edges = list(solid.Edges)
    # Each edge's faces from one pass over the faces' edges. `ancestorsOfType` maps the whole
    # solid again at each call: 7 ms an edge on a solid converted from a mesh (10,026 edges:
    # 70 s of a 93 s plan).
    by_hash: dict[int, list[int]] = {}
    owners: dict[int, list[int]] = {}
    for edge_index, edge in enumerate(edges):
        if only is not None and not only(edge):
            continue  # before the face search: on a piece most edges are left out
        by_hash.setdefault(hash_code(edge), []).append(edge_index)
        owners[edge_index] = []
    for face_index, face in enumerate(faces):
        for face_edge in face.Edges:
            for edge_index in by_hash.get(hash_code(face_edge), ()):
                found = owners[edge_index]
                if is_same(edges[edge_index], face_edge) and face_index not in found:
                    found.append(face_index)
    result = []
    for edge_index, pair in sorted(owners.items()):
        if len(pair) != 2:
            continue
        edge = edges[edge_index]
        if edge.Length <= 0 or edge.isSeam(faces[pair[0]]):
            continue
        angle = _cached_angle(App, edge, faces[pair[0]], faces[pair[1]])
        result.append(EdgeAngle(edge_index, (pair[0], pair[1]), angle, edge))
    return result


#: Inner angles already measured, by edge and faces (`shape_cache.py`): the decomposition
#: asks again for every piece, and a split leaves most edges and their faces untouched. The
#: orientations count: they fix the normals the angle is read from.
_ANGLES: ShapeCache[float] = ShapeCache(limit=20000, oriented=True)


def _cached_angle(App, edge, face1, face2) -> float:
    return _ANGLES.get((edge, face1, face2), lambda: _inner_angle(App, edge, face1, face2))


def _inner_angle(App, edge, face1, face2) -> float:
    first, last = edge.ParameterRange
    probe = max(PROBE_FRACTION * edge.Length, 1e-5)
    parameters = [first + fraction * (last - first) for fraction in SAMPLE_FRACTIONS]
    points = [edge.valueAt(t) for t in parameters]
    samples = list(zip([_vec(point) for point in points],
                       [_vec(edge.tangentAt(t)) for t in parameters],
                       _normals_along(face1, edge, parameters, points),
                       _normals_along(face2, edge, parameters, points)))
    # Which side of the edge face 1 lies on holds along the whole edge (n1 × t turns
    # continuously): its orientation in face 1 tells, else probes in the middle do.
    sign = side_in_face(edge, face1)
    if sign is None:
        p, t, n1, _ = samples[len(samples) // 2]
        sign = 1.0 if into_face(face1, p, t, n1, probe) @ np.cross(n1, t) > 0 else -1.0
    angles = []
    for p, t, n1, n2 in samples:
        b1 = sign * np.cross(n1, t)
        turn = math.acos(float(np.clip(n1 @ n2, -1.0, 1.0)))
        angles.append(math.pi + turn if b1 @ n2 > 0 else math.pi - turn)
    return float(np.median(angles))


#: An edge's orientation in a face: OCC orients a face's boundary so that the face lies on
#: the left of each edge, seen from the outward normal (the face's orientation counted in
#: both: FreeCAD's `Face.normalAt` and `Face.Edges` compose it).
_LEFT_OF_EDGE = {"Forward": 1.0, "Reversed": -1.0}


def side_in_face(edge, face) -> float | None:
    """+1 when `face` lies on the side n × t of `edge` (n its outward normal, t the edge's
    curve tangent), −1 on the other; None for a seam of the face (on both sides of it), an
    internal edge or one the face does not hold. Read from the topology instead of probing
    each side (four point projections, and the exact distance where they disagree: 1.4 ms an
    edge of CrankArm's arm; there, 2 µm either side of two edges, both probes met a narrow
    B-spline face)."""
    if edge.isSeam(face):
        return None     # `Face.Edges` lists it once, with one of its two orientations
    found = [e.Orientation for e in face.Edges if e.isSame(edge)]
    if len(found) != 1:
        return None
    return _LEFT_OF_EDGE.get(found[0])


def concave_edges(solid, within: list[EdgeAngle] | None = None) -> list[EdgeAngle]:
    """The concave edges of `solid` (inner angle over 180° + SMOOTH_ANGLE).

    `within`: the concave edges of a solid that `solid` was cut from by planes. A planar cut
    leaves material on one side of its plane only, so every edge it makes is convex or flat,
    and the other edges keep the two surfaces they had: the concave edges of a piece lie on
    its ancestor's. Only those are measured (CrankArm's turned arm: 198 of 634). They
    are measured again, not copied: a cut in the plane of one of the two faces flattens
    the edge."""
    if within is None:
        return [e for e in edge_angles(solid) if e.concave]
    if not within:
        return []
    return [e for e in edge_angles(solid, only=lambda edge: _lies_on_any(edge, within))
            if e.concave]


#: A point lies on an edge's curve within this (mm): sub-edges of a split keep their curve,
#: so their points are on it to rounding; far below any feature.
ON_CURVE = 1e-5


def _lies_on_any(edge, known: list[EdgeAngle]) -> bool:
    """Whether `edge` lies on the curve of one of the `known` edges (tested at two interior
    points; a point of the same curve outside the known edge passes too, which only costs
    one exact measurement)."""
    if any(k.edge.isSame(edge) for k in known):
        return True
    first, last = edge.ParameterRange
    points = [edge.valueAt(first + f * (last - first)) for f in (1 / 3, 2 / 3)]
    for k in known:
        if not all(_in_box(optimal_box(k.edge), p, 10 * ON_CURVE) for p in points):
            continue
        curve = k.edge.Curve
        if all((curve.value(curve.parameter(p)) - p).Length < ON_CURVE for p in points):
            return True
    return False


def _in_box(box, p, margin: float) -> bool:
    """Whether point p lies in the box grown by `margin` (the box itself is shared)."""
    return (box.XMin - margin <= p.x <= box.XMax + margin
            and box.YMin - margin <= p.y <= box.YMax + margin
            and box.ZMin - margin <= p.z <= box.ZMax + margin)
