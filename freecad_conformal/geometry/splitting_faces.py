"""Planar splitting faces: where a solid can be cut into sub-parts, and the exact cut.

A candidate plane carries a planar face of the part that has a concave edge on its boundary
(METHODS section 3, criterion 2). The cut is not the whole plane: only the region of the
plane's section that lies inside the material and touches that concave edge, so a plane
through a column's side does not also slice an unrelated base beside it.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from freecad_conformal.errors import GeometryError
from freecad_conformal.geometry.solids import occ_confusion, passes_check
from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry.concave_edges import EdgeAngle

#: A region touches an edge when closer than this (mm).
TOUCH_TOLERANCE = 1e-5

#: Pieces smaller than this fraction of the solid's volume are slivers of a Boolean.
SLIVER_FRACTION = 1e-9


@dataclass
class SplitCandidate:
    """One planar region to cut along; `normal` is the plane's normal (unit), `rule` tells
    which rule proposed it ("concave-face", "area-jump", "branch" or "flange")."""

    point: np.ndarray
    normal: np.ndarray
    region: object
    rule: str
    face_index: int | None = None
    #: points of the region's outline when `region` is not an exact face (a mesh trial)
    boundary: np.ndarray | None = None

    @property
    def level(self) -> float:
        return float(self.point @ self.normal)


def _vec(v) -> np.ndarray:
    return np.array([v.x, v.y, v.z])


def plane_through(point: np.ndarray, normal: np.ndarray, box):
    """A square planar face through `point` normal to `normal`, covering `box` with margin."""
    App, Part = import_freecad()
    half = box.DiagonalLength + 1.0
    centre = _vec(box.Center)
    centre = centre - ((centre - point) @ normal) * normal
    plane = Part.Plane(App.Vector(*centre), App.Vector(*normal))
    return plane.toShape(-half, half, -half, half)


def _inner_point(face) -> np.ndarray:
    """A point inside the face: its centre of mass when inside, else a triangle centre."""
    App, _ = import_freecad()
    com = face.CenterOfMass
    if face.isInside(com, occ_confusion(), True):
        return _vec(com)
    points, triangles = face.tessellate(0.1)
    a, b, c = (np.array(tuple(points[i])) for i in triangles[0])
    return (a + b + c) / 3.0


def interior_regions(solid, point: np.ndarray, normal: np.ndarray) -> list:
    """Faces of the plane's section that lie inside the material (not on the boundary).

    Every section face lies in the closed solid; it is boundary (material on one side only)
    exactly where it lies on a face of the solid in the same plane. So a face whose inner
    point is on such a face is dropped: a 2D classification in that face, instead of two 3D
    inside tests (which cost ~8 ms each on B-spline solids)."""
    App, _ = import_freecad()
    on_plane = faces_on_plane(solid, point, normal)
    regions = []
    for face in solid.common(plane_through(point, normal, solid.BoundBox)).Faces:
        if face.Area <= 1e-9:
            continue
        probe = App.Vector(*_inner_point(face))
        if not any(other.isInside(probe, ON_FACE, True) for other in on_plane):
            regions.append(face)
    return regions


#: A section face's inner point lies on a boundary face of the solid within this (mm):
#: OCC's default confusion, both being exact faces in one plane.
ON_FACE = 1e-7


def faces_on_plane(solid, point: np.ndarray, normal: np.ndarray) -> list:
    """The solid's planar faces lying in the plane through `point` normal to `normal`."""
    from freecad_conformal.geometry.face_normals import plane_normal

    faces = []
    for face in solid.Faces:
        n = plane_normal(face)
        if n is None or 1.0 - abs(float(n @ normal)) > SAME_PLANE_COS:
            continue
        if abs(float((_vec(face.Vertexes[0].Point) - point) @ normal)) < ON_PLANE:
            faces.append(face)
    return faces


#: Two faces lie on one plane when their normals agree to this (1 − |cos|) and their levels
#: to ON_PLANE (mm): the region search then runs once for the plane.
SAME_PLANE_COS = 1e-9
ON_PLANE = 1e-6


@dataclass
class CandidatePlane:
    """The plane of one or more planar faces carrying concave edges (criterion 2), before
    its interior regions are computed (a Boolean and inside tests: done only for the planes
    a decomposition ranks worth cutting). `faces` pairs each face index with its concave
    edges, in face order."""

    point: np.ndarray
    normal: np.ndarray
    faces: list[tuple[int, list[EdgeAngle]]]

    @property
    def face_index(self) -> int:
        return self.faces[0][0]

    def probe(self, rule: str = "concave-face") -> SplitCandidate:
        """A region-less candidate on this plane, for estimates that read only the plane."""
        return SplitCandidate(self.point, self.normal, None, rule, self.face_index)


def candidate_planes(solid, concave: list[EdgeAngle]) -> list[CandidatePlane]:
    """Planes of the planar faces that carry a concave edge, one per distinct plane."""
    from freecad_conformal.geometry.face_normals import plane_normal

    faces = list(solid.Faces)
    edges_of: dict[int, list[EdgeAngle]] = {}
    for edge in concave:
        for index in edge.faces:
            edges_of.setdefault(index, []).append(edge)
    planes: list[CandidatePlane] = []
    for index, edge_list in sorted(edges_of.items()):
        normal = plane_normal(faces[index])
        if normal is None:
            continue
        point = _vec(faces[index].Vertexes[0].Point)
        for plane in planes:
            if (1.0 - abs(float(plane.normal @ normal)) < SAME_PLANE_COS
                    and abs(float((point - plane.point) @ plane.normal)) < ON_PLANE):
                plane.faces.append((index, edge_list))
                break
        else:
            planes.append(CandidatePlane(point, normal, [(index, edge_list)]))
    return planes


def plane_regions(solid, plane: CandidatePlane) -> list[SplitCandidate]:
    """The plane's interior regions that touch one of its faces' concave edges, each as a
    candidate credited to the first face whose edge it touches."""
    candidates: list[SplitCandidate] = []
    for region in interior_regions(solid, plane.point, plane.normal):
        for index, edge_list in plane.faces:
            if any(region.distToShape(e.edge)[0] < TOUCH_TOLERANCE for e in edge_list):
                candidates.append(SplitCandidate(plane.point, plane.normal, region,
                                                 "concave-face", index))
                break
    return candidates


def face_candidates(solid, concave: list[EdgeAngle]) -> list[SplitCandidate]:
    """Regions on the planes of planar faces that carry a concave edge (criterion 2)."""
    return [candidate for plane in candidate_planes(solid, concave)
            for candidate in plane_regions(solid, plane)]


#: `Shape.fix` settings for Boolean pieces OCC's checker rejects (CrankArm's B-spline cuts
#: leave "not connected" / "unorientable" wires): working precision and the range its
#: tolerances may take; the geometry is not moved.
FIX_PRECISION = 1e-7
FIX_MAX_TOLERANCE = 1e-4


def repaired(solid):
    """The solid, or a copy fixed by OCC's shape healing when its checker rejects it and the
    fix passes the check without changing the volume (else the solid as it was). The check
    is remembered (`solids.passes_check`): the sub-part's copies laid out on the platform
    are not checked again when sliced (CrankArm: 0.17 s)."""
    if passes_check(solid):
        return solid
    fixed = solid.copy()
    fixed.fix(FIX_PRECISION, FIX_PRECISION, FIX_MAX_TOLERANCE)
    if fixed.isValid() and abs(fixed.Volume - solid.Volume) <= 1e-9 * max(abs(solid.Volume), 1.0):
        return fixed
    return solid


#: Fuzzy value (mm) of the second try of a split OCC did not make: CrankArm's B-spline arm,
#: cut along regions of its planar faces, comes back whole or without a piece, and with
#: 1e-6 mm of fuzz splits into pieces whose volumes sum to the arm's.
SPLIT_FUZZ = 1e-6

#: A split that leaves more than this fraction of the volume unaccounted lost a piece
#: (Booleans on B-splines otherwise lose ~1e-5).
LOST_VOLUME = 1e-4


def split_solid(solid, regions: list) -> list:
    """The solid cut by the planar regions (exact Boolean), as a list of solids."""
    if not regions:
        return [solid]
    # Volumes of B-spline pieces cost ~20 ms each: read once.
    volume = float(solid.Volume)
    pieces = _split(solid, regions, 0.0, volume)
    if len(pieces) < 2 or _lost(volume, pieces):
        again = _split(solid, regions, SPLIT_FUZZ, volume)
        if len(again) >= 2 and not _lost(volume, again):
            pieces = again
    return [piece for piece, _ in pieces]


def _lost(volume: float, pieces: list) -> bool:
    return sum(v for _, v in pieces) < (1.0 - LOST_VOLUME) * volume


def _split(solid, regions: list, fuzz: float, volume: float) -> list[tuple[object, float]]:
    """(piece, volume) of the split's solids above the sliver size."""
    try:
        result, _ = solid.generalFuse(list(regions), fuzz) if fuzz else solid.generalFuse(list(regions))
    except Exception as exc:  # OCC Boolean failures surface as plain exceptions
        raise GeometryError(f"splitting a solid of volume {volume:.6g} mm³ failed: {exc}") from exc
    measured = [(piece, float(piece.Volume)) for piece in result.Solids]
    pieces = [(piece, v) for piece, v in measured if v > SLIVER_FRACTION * volume]
    return pieces or [(solid, volume)]
