"""Overhang (support) area of a solid built along a direction.

A point of the surface overhangs when its outward normal n faces down more steeply than the
allowed angle α from the build direction d: n·d < −sin α (a wall, n ⊥ d, is 0° of overhang;
a ceiling, n = −d, is 90°). Planar faces are exact (`Face.Area`); curved faces are integrated
on a fine triangulation whose triangle normals are oriented as OCC's face normal, and the
sum is scaled by Face.Area / triangulated area so the chord error does not bias the total.
Faces resting on the bed (the lowest plane) or on the parent's split faces are excluded.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from freecad_conformal.errors import PlanError
from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry.shape_cache import ShapeCache

#: Default allowed overhang from the build direction (the common 45° self-support rule of FDM).
DEFAULT_OVERHANG_ANGLE = math.radians(45.0)

#: Triangulation deflection relative to the face's bounding-box diagonal for curved faces:
#: 0.2 % keeps the normal error of a triangle under ~2° on the real parts' fillets and cones.
RELATIVE_DEFLECTION = 1e-2

#: A planar face counts as lying on a plane (bed, split face) within this distance (mm):
#: far above OCC's 1e-7 confusion, far below any layer height.
ON_PLANE_TOLERANCE = 1e-4

#: Overhang areas below this (mm²) are rounding: slivers of tangent faces.
NEGLIGIBLE_AREA = 1e-6


@dataclass
class OverhangReport:
    """Overhang area (mm²) of one solid in one direction, with the faces that contribute."""

    direction: np.ndarray
    angle: float
    area: float
    faces: list[tuple[int, float]] = field(default_factory=list)

    def to_dict(self) -> dict:
        return {"direction": [float(c) for c in self.direction],
                "angle_deg": math.degrees(self.angle), "area": self.area,
                "faces": [{"face": f"Face{i + 1}", "area": a} for i, a in self.faces]}


def _direction(direction: Sequence[float]) -> np.ndarray:
    d = np.asarray(direction, dtype=float).reshape(-1)
    if d.shape != (3,) or not np.all(np.isfinite(d)) or np.linalg.norm(d) < 1e-12:
        raise PlanError(f"build direction must be a non-zero 3-vector, got {list(np.ravel(direction))!r}")
    return d / np.linalg.norm(d)


def check_angle(angle: float) -> float:
    if not (math.isfinite(angle) and 0.0 <= angle < math.pi / 2):
        raise PlanError(f"allowed overhang angle must be in [0°, 90°), got {math.degrees(angle):g}°")
    return float(angle)


def plane_normal(face) -> np.ndarray | None:
    """The outward unit normal of a planar face, None for any other surface."""
    if type(face.Surface).__name__ != "Plane":
        return None
    u0, u1, v0, v1 = face.ParameterRange
    n = face.normalAt(0.5 * (u0 + u1), 0.5 * (v0 + v1))
    return np.array([n.x, n.y, n.z])


def lowest_level(shape, d: np.ndarray) -> float:
    """Lowest height of the shape's vertices along d (planar bottoms are bounded by vertices;
    curved bottoms do not rest on the bed flat anyway)."""
    return float(min(np.array(tuple(v.Point)) @ d for v in shape.Vertexes))


@dataclass
class FaceMesh:
    """A curved face's triangulation with exact normals at the nodes: node normals (M, 3)
    from OCC, triangles (N, 3) into them, and triangle areas (N,) scaled so they sum to the
    exact Face.Area (the chord error then does not bias a total)."""

    normals: np.ndarray
    triangles: np.ndarray
    areas: np.ndarray

    def overhang(self, d: np.ndarray, threshold: float) -> float:
        """Area where n·d < −threshold. n·d is taken linear over each triangle between the
        exact node values and the triangle clipped where it crosses the limit, so the cap
        boundary is found to second order instead of to a whole triangle."""
        if not len(self.areas):
            return 0.0
        return float(self.areas @ below_fraction((self.normals @ d + threshold)[self.triangles]))


def below_fraction(g: np.ndarray) -> np.ndarray:
    """Per triangle, the fraction of its area where a function linear over it, with values
    g (K, 3) at its corners, is negative."""
    g = np.sort(g, axis=1)
    g0, g1, g2 = g[:, 0], g[:, 1], g[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        one_below = np.where((g0 < 0) & (g1 >= 0), g0 * g0 / ((g0 - g1) * (g0 - g2)), 0.0)
        two_below = np.where((g1 < 0) & (g2 >= 0), 1 - g2 * g2 / ((g2 - g0) * (g2 - g1)), 0.0)
    return np.where(g2 < 0, 1.0, np.nan_to_num(one_below) + np.nan_to_num(two_below))


#: Meshes of faces already read (`geometry/shape_cache.py`): a split leaves most faces of
#: a piece untouched, and the same pieces are evaluated several times while cuts are compared.
_MESHES: ShapeCache[FaceMesh] = ShapeCache(limit=4096, oriented=True)

#: Tessellation points and the triangulation's UV nodes are matched by position rounded to
#: this (mm): far below the mesh spacing, far above the 1e-12 scatter of one evaluation.
NODE_MATCH = 1e-6


def face_mesh(face) -> FaceMesh:
    """The triangulation of a curved face with OCC's exact normals at its nodes (the face's
    part of its solid's mesh when the decomposition made one: geometry/surface_mesh.py)."""
    return _MESHES.get((face,), lambda: _from_part(face) or _build_mesh(face))


def _from_part(face) -> FaceMesh | None:
    from freecad_conformal.geometry.surface_mesh import known_part

    part = known_part(face)
    if part is None:
        return None
    points, triangles, corners, _, ratio = part
    a, b, c = (points[triangles[:, k]] for k in range(3))
    areas = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1) * ratio
    return FaceMesh(np.asarray(corners).reshape(-1, 3), np.arange(3 * len(triangles)).reshape(-1, 3),
                    areas)


def _empty_mesh() -> FaceMesh:
    return FaceMesh(np.zeros((0, 3)), np.zeros((0, 3), dtype=int), np.zeros(0))


def _node_normals(face, points: np.ndarray) -> np.ndarray:
    """OCC's exact normals (face orientation applied) at the tessellation points, zero where
    the surface has none (poles, apexes). Read at the triangulation's own UV nodes through
    the surface (Surface.normal is ~60x cheaper than Face.normalAt, and no point has to be
    projected back with Surface.parameter); the nodes are matched to the points by position."""
    surface = face.Surface
    uv = face.getUVNodes()
    normals = np.zeros((len(uv), 3))
    for k, (u, v) in enumerate(uv):
        try:
            normals[k] = tuple(surface.normal(u, v))
        except Exception:  # OCC raises where the normal is undefined (poles, apexes)
            normals[k] = 0.0
    if face.Orientation == "Reversed":
        normals = -normals
    nodes = np.array([tuple(surface.value(u, v)) for u, v in uv]).reshape(-1, 3)
    # Reversed so the first of duplicate nodes (a seam) is the one kept.
    where = dict(zip(reversed(_position_keys(nodes)), range(len(uv) - 1, -1, -1)))
    result = np.zeros((len(points), 3))
    for i, key in enumerate(_position_keys(points)):
        k = where.get(key)
        if k is None:  # a rounding boundary between the two evaluations: ask exactly
            result[i] = tuple(face.normalAt(*surface.parameter(_vector(points[i]))))
        else:
            result[i] = normals[k]
    return result


def _position_keys(points: np.ndarray) -> list[tuple]:
    return [tuple(row) for row in np.round(points / NODE_MATCH).astype(np.int64).tolist()]


def _vector(point: np.ndarray):
    App, _ = import_freecad()
    return App.Vector(*(float(c) for c in point))


def _build_mesh(face) -> FaceMesh:
    box = face.BoundBox
    deflection = max(RELATIVE_DEFLECTION * box.DiagonalLength, 1e-3)
    # On a copy, forced: OCC keeps a finer mesh from earlier calls otherwise (the area would
    # depend on what else meshed the face before), and re-meshing the face itself would
    # leave its edges unlike its neighbours' in the solid's mesh (geometry/surface_mesh.py).
    face = face.copy()
    points, triangles = face.tessellate(deflection, True)
    if not triangles:
        return _empty_mesh()
    pts = np.array([tuple(p) for p in points])
    tri = np.asarray(triangles, dtype=int)
    a, b, c = pts[tri[:, 0]], pts[tri[:, 1]], pts[tri[:, 2]]
    cross = np.cross(b - a, c - a)
    areas = 0.5 * np.linalg.norm(cross, axis=1)
    keep = areas > 0
    tri, cross, areas = tri[keep], cross[keep], areas[keep]
    if not len(areas):
        return _empty_mesh()
    flat = cross / (2.0 * areas[:, None])
    normals = _node_normals(face, pts)
    length = np.linalg.norm(normals, axis=1)
    # Poles of spheres and cone apexes have no normal: those nodes take the mean of the
    # flat normals of their triangles (oriented as OCC's below).
    bad = length < 1e-9
    normals[~bad] /= length[~bad, None]
    if bad.any():
        sign = np.sign(np.einsum("ij,ij->i", flat, normals[tri].sum(axis=1)))
        oriented = flat * np.where(sign == 0, 1.0, sign)[:, None]
        for node in np.nonzero(bad)[0]:
            mean = oriented[np.any(tri == node, axis=1)].sum(axis=0)
            normals[node] = mean / max(np.linalg.norm(mean), 1e-12)
    return FaceMesh(normals, tri, areas * (float(face.Area) / float(areas.sum())))


def _curved_overhang(face, d: np.ndarray, threshold: float) -> float:
    return face_mesh(face).overhang(d, threshold)


def overhang_report(shape, direction: Sequence[float], angle: float = DEFAULT_OVERHANG_ANGLE,
                    base_faces: Sequence = (), on_bed: bool = True) -> OverhangReport:
    """Area of `shape`'s faces overhanging more than `angle` when built along `direction`.

    Args:
        shape: a solid (or compound) in the part's frame.
        direction: build direction (layers stack along it).
        angle: allowed overhang from the build direction (rad).
        base_faces: planar faces the shape is built on (its parent's split faces); the part of a
            face covered by them is not overhang.
        on_bed: also exclude faces lying on the lowest plane (the build plate).
    """
    d = _direction(direction)
    threshold = math.sin(check_angle(angle))
    low = lowest_level(shape, d) if on_bed else None
    faces = []
    for index, face in enumerate(shape.Faces):
        normal = plane_normal(face)
        if normal is None:
            area = _curved_overhang(face, d, threshold)
        elif normal @ d < -threshold:
            area = float(face.Area) - _supported_area(face, normal, d, low, base_faces)
        else:
            area = 0.0
        if area > NEGLIGIBLE_AREA:
            faces.append((index, area))
    return OverhangReport(direction=d, angle=angle, area=float(sum(a for _, a in faces)),
                          faces=faces)


def overhang_area(shape, direction: Sequence[float], angle: float = DEFAULT_OVERHANG_ANGLE,
                  base_faces: Sequence = (), on_bed: bool = True) -> float:
    """Total overhang area (mm²); see `overhang_report`."""
    return overhang_report(shape, direction, angle, base_faces, on_bed).area


def _supported_area(face, normal: np.ndarray, d: np.ndarray, low: float | None,
                    base_faces: Sequence) -> float:
    """How much of a downward planar face rests on the bed or on the base faces."""
    level = float(np.array(tuple(face.Vertexes[0].Point)) @ d)
    if low is not None and abs(normal @ d + 1.0) < 1e-9 and abs(level - low) < ON_PLANE_TOLERANCE:
        return float(face.Area)
    supported = 0.0
    for base in base_faces:
        base_normal = plane_normal(base)
        if base_normal is None or abs(abs(base_normal @ normal) - 1.0) > 1e-9:
            continue
        if abs(float(np.array(tuple(base.Vertexes[0].Point)) @ normal)
               - float(np.array(tuple(face.Vertexes[0].Point)) @ normal)) > ON_PLANE_TOLERANCE:
            continue
        if not face.BoundBox.intersect(base.BoundBox):
            continue
        supported += float(face.common(base).Area)
    return min(supported, float(face.Area))


#: Candidate single directions for the whole part: the six axis directions.
AXIS_DIRECTIONS = tuple(np.array(v, dtype=float) for v in
                        ((0, 0, 1), (0, 0, -1), (1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0)))


def best_single_direction(shape, angle: float = DEFAULT_OVERHANG_ANGLE,
                          candidates: Sequence[np.ndarray] = AXIS_DIRECTIONS
                          ) -> tuple[np.ndarray, float]:
    """The candidate direction with the least overhang for the whole part, and that area."""
    best = None
    for candidate in candidates:
        area = overhang_area(shape, candidate, angle)
        if best is None or area < best[1] - NEGLIGIBLE_AREA:
            best = (np.asarray(candidate, dtype=float), area)
    return best
