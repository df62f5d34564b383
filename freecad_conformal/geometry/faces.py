"""Face analysis: surface type, principal curvatures and directions, smallest radius, normals.

Everything is read from OpenCASCADE: the surface's first and second derivatives at (u, v)
give the first and second fundamental forms, whose shape operator has the principal
curvatures as eigenvalues and the principal directions as eigenvectors (exact to floating
point, no mesh). The normal is the face's own (`Face.normalAt`), so a reversed face (the
inside of a hole) has its normal pointing out of the material too.

Sign convention: a curvature is positive where the face bends away from its outward normal
(convex, the outside of a ball: κ = +1/R) and negative where it bends towards it (concave,
the inside of a bore: κ = −1/R); 0 on a plane or along a straight generator.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from freecad_conformal.errors import GeometryError
from freecad_conformal.freecad_env import import_freecad

FACE_KINDS = ("plane", "cylinder", "cone", "sphere", "torus", "bspline", "other")

#: OCC surface class name -> face kind.
_SURFACE_KINDS = {"Plane": "plane", "Cylinder": "cylinder", "Cone": "cone", "Sphere": "sphere",
                  "Toroid": "torus", "BSplineSurface": "bspline", "BezierSurface": "bspline"}

#: A curvature below this (1/mm) is flat: a radius over 1e9 mm (1000 km) is no constraint on
#: any tool, and the value keeps 1/κ finite without dividing by rounding noise.
FLAT_CURVATURE = 1e-9

#: Grid used to search the smallest radius on surfaces without a closed form (per direction).
#: 24 × 24 samples find the region of the extreme curvature on the bottle's thread faces;
#: a local pattern search then refines it to `REFINE_TOLERANCE` of the parameter range.
SEARCH_GRID = 24
REFINE_TOLERANCE = 1e-6

#: A point whose area element |Su × Sv| is below this fraction of the face's median is
#: treated as a pole (NURBS spheres, pinched thread ends): the derivatives there are
#: dominated by rounding (a NURBS sphere loses ~5 digits of curvature at 1e-6) and the
#: curvature read from them is not the surface's.
POLE_FRACTION = 1e-4

FACE_NAME = re.compile(r"^Face(\d+)$")


@dataclass(frozen=True)
class Curvature:
    """Principal curvatures at one point: k1 ≥ k2 (1/mm, signed as the module says),
    their unit tangent directions d1, d2, and the outward unit normal."""

    point: np.ndarray
    normal: np.ndarray
    k1: float
    k2: float
    d1: np.ndarray
    d2: np.ndarray

    @property
    def radii(self) -> tuple[float, float]:
        """Principal radii 1/k1, 1/k2 (signed; math.inf for a flat direction)."""
        return tuple(1.0 / k if abs(k) > FLAT_CURVATURE else math.inf for k in (self.k1, self.k2))

    @property
    def smallest_radius(self) -> float:
        """The smallest |radius| at this point (math.inf where the surface is flat)."""
        k = max(abs(self.k1), abs(self.k2))
        return 1.0 / k if k > FLAT_CURVATURE else math.inf


@dataclass(frozen=True)
class FaceInfo:
    """What a face is: its kind, area, and the defining data of analytic surfaces.

    `axis` is the axis direction (cylinder, cone, torus, sphere's pole) or the plane normal;
    `center` the axis location, cone apex, sphere or torus centre; `radius` the cylinder or
    sphere radius (torus: major), `minor_radius` the torus tube radius, `semi_angle` the
    cone's half angle (rad). `smallest_radius` is over the whole face (math.inf for a plane).
    """

    name: str
    kind: str
    area: float
    smallest_radius: float
    axis: np.ndarray | None = None
    center: np.ndarray | None = None
    radius: float | None = None
    minor_radius: float | None = None
    semi_angle: float | None = None

    def summary(self) -> str:
        extra = ""
        if self.radius is not None:
            extra += f" r {self.radius:.4g} mm"
        if self.semi_angle is not None:
            extra += f" half angle {math.degrees(self.semi_angle):.4g}°"
        rs = "flat" if math.isinf(self.smallest_radius) else f"{self.smallest_radius:.4g} mm"
        return f"{self.name}: {self.kind}{extra}, area {self.area:.4g} mm², smallest radius {rs}"


def _vec(v) -> np.ndarray:
    return np.array([v.x, v.y, v.z], dtype=float)


def face_kind(face) -> str:
    """One of FACE_KINDS for an OCC face."""
    return _SURFACE_KINDS.get(face.Surface.__class__.__name__, "other")


def face_by_name(shape, name: str, what: str = "part"):
    """The face called `name` ("Face7", FreeCAD's 1-based naming) of `shape`.

    Raises GeometryError naming the face and the faces the shape has.
    """
    match = FACE_NAME.match(str(name).strip())
    count = len(shape.Faces)
    if not match:
        raise GeometryError(f"face name {name!r} is not of the form FaceN (the {what} has "
                            f"faces Face1..Face{count})")
    index = int(match.group(1))
    if not 1 <= index <= count:
        raise GeometryError(f"face {name} is not in the {what}: it has {count} faces "
                            f"(Face1..Face{count})")
    return shape.Faces[index - 1]


def principal_curvatures(face, u: float, v: float) -> Curvature:
    """Principal curvatures and directions of `face` at parameters (u, v), from OCC's exact
    derivatives. Raises GeometryError at a singular point (degenerate tangent plane)."""
    App, _ = import_freecad()
    surface = face.Surface
    su = _vec(surface.getDN(u, v, 1, 0))
    sv = _vec(surface.getDN(u, v, 0, 1))
    suu = _vec(surface.getDN(u, v, 2, 0))
    suv = _vec(surface.getDN(u, v, 1, 1))
    svv = _vec(surface.getDN(u, v, 0, 2))
    normal = _vec(face.normalAt(u, v))
    e, f, g = su @ su, su @ sv, sv @ sv
    det = e * g - f * f
    if not det > 1e-24 * max(e * g, 1e-300):
        raise GeometryError(f"the surface of the face is singular at (u, v) = ({u:.6g}, {v:.6g}) "
                            "(no tangent plane: a cone apex or sphere pole)")
    # Second form with the outward normal; minus sign so convex bends count positive.
    ll, mm, nn = -(suu @ normal), -(suv @ normal), -(svv @ normal)
    first = np.array([[e, f], [f, g]])
    second = np.array([[ll, mm], [mm, nn]])
    shape_operator = np.linalg.solve(first, second)
    values, vectors = np.linalg.eig(shape_operator)
    values, vectors = values.real, vectors.real
    order = np.argsort(values)[::-1]
    tangents = []
    for k in order:
        t = vectors[0, k] * su + vectors[1, k] * sv
        tangents.append(t / np.linalg.norm(t))
    if abs(values[order[0]] - values[order[1]]) <= FLAT_CURVATURE:
        # Umbilic point (sphere, plane): every direction is principal; take an orthonormal pair.
        t1 = su / np.linalg.norm(su)
        tangents = [t1, np.cross(normal, t1)]
    point = _vec(face.valueAt(u, v))
    return Curvature(point=point, normal=normal, k1=float(values[order[0]]),
                     k2=float(values[order[1]]), d1=tangents[0], d2=tangents[1])


def parameters_of(face, points: np.ndarray) -> np.ndarray:
    """(N, 2) surface parameters (u, v) of points (N, 3) on or near the face (projection)."""
    App, _ = import_freecad()
    surface = face.Surface
    return np.array([surface.parameter(App.Vector(*map(float, p))) for p in np.atleast_2d(points)],
                    dtype=float)


def curvature_at_point(face, point) -> Curvature:
    """Principal curvatures at the face point closest to `point`."""
    u, v = parameters_of(face, np.asarray(point, dtype=float).reshape(1, 3))[0]
    return principal_curvatures(face, float(u), float(v))


def normals_at(face, uv: np.ndarray) -> np.ndarray:
    """(N, 3) outward unit normals at parameters uv (N, 2): the tool-orientation field."""
    rows = [_vec(face.normalAt(float(u), float(v))) for u, v in np.atleast_2d(uv)]
    normals = np.array(rows, dtype=float).reshape(-1, 3)
    return normals / np.linalg.norm(normals, axis=1)[:, None]


def points_at(face, uv: np.ndarray) -> np.ndarray:
    """(N, 3) surface points at parameters uv (N, 2)."""
    return np.array([_vec(face.valueAt(float(u), float(v))) for u, v in np.atleast_2d(uv)],
                    dtype=float).reshape(-1, 3)


def domain_grid(face, count: int = SEARCH_GRID) -> np.ndarray:
    """(M, 2) parameters of a count × count grid over the face's UV box, kept where they lie
    on the face (inside its trimming loops). Grid points sit at cell centres, never on the
    boundary, so poles and seams are avoided."""
    u0, u1, v0, v1 = face.ParameterRange
    fractions = (np.arange(count) + 0.5) / count
    uu, vv = np.meshgrid(u0 + (u1 - u0) * fractions, v0 + (v1 - v0) * fractions, indexing="ij")
    grid = np.column_stack((uu.ravel(), vv.ravel()))
    inside = np.array([face.isPartOfDomain(float(u), float(v)) for u, v in grid], dtype=bool)
    return grid[inside]


def smallest_radius(face) -> float:
    """Smallest |principal radius| over the face (mm); math.inf for a plane.

    Closed forms for planes, cylinders, spheres, cones (the smallest circle of the face,
    radius ρ/cos α) and tori (tube radius r, or |ρ/cos φ| along the minor angle); on other
    surfaces a grid search over the face refined by a local pattern search.
    """
    kind = face_kind(face)
    surface = face.Surface
    if kind == "plane":
        return math.inf
    if kind in ("cylinder", "sphere"):
        return float(surface.Radius)
    u0, u1, v0, v1 = face.ParameterRange
    if kind == "cone":
        alpha = float(surface.SemiAngle)
        rho = min(abs(float(surface.Radius) + v * math.sin(alpha)) for v in (v0, v1))
        return rho / math.cos(alpha)
    if kind == "torus":
        # The other radius is |R/cos φ + r|, stationary only where sin φ = 0: its minimum
        # over [v0, v1] is at an end or at a multiple of π inside.
        major, minor = float(surface.MajorRadius), float(surface.MinorRadius)
        candidates = [v0, v1] + [k * math.pi for k in range(math.ceil(v0 / math.pi),
                                                            math.floor(v1 / math.pi) + 1)]
        meridian = [abs(major / math.cos(p) + minor) for p in candidates if abs(math.cos(p)) > 1e-15]
        return float(min([minor] + meridian))
    return _searched_smallest_radius(face)


def _area_element(face, u: float, v: float) -> float:
    surface = face.Surface
    return float(np.linalg.norm(np.cross(_vec(surface.getDN(u, v, 1, 0)),
                                         _vec(surface.getDN(u, v, 0, 1)))))


def _radius_or_inf(face, u: float, v: float, min_element: float) -> float:
    if _area_element(face, u, v) < min_element:
        return math.inf
    try:
        return principal_curvatures(face, u, v).smallest_radius
    except GeometryError:
        return math.inf


def _searched_smallest_radius(face) -> float:
    """Grid search then pattern search, skipping poles (see POLE_FRACTION). Where a surface
    pinches to a point (a thread's run-out) the radius tends to 0 towards it and the result
    is the smallest met on the way there."""
    grid = domain_grid(face)
    if len(grid) == 0:
        raise GeometryError("face has no interior sample point to measure its curvature")
    min_element = POLE_FRACTION * float(np.median([_area_element(face, u, v) for u, v in grid]))
    radii = np.array([_radius_or_inf(face, u, v, min_element) for u, v in grid])
    best = int(np.argmin(radii))
    u, v = grid[best]
    r = float(radii[best])
    u0, u1, v0, v1 = face.ParameterRange
    step = np.array([(u1 - u0), (v1 - v0)]) / SEARCH_GRID
    while np.all(step > REFINE_TOLERANCE * np.array([u1 - u0, v1 - v0])):
        moved = False
        for du, dv in ((1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (-1, -1), (1, -1), (-1, 1)):
            cu, cv = u + du * step[0], v + dv * step[1]
            if not (u0 <= cu <= u1 and v0 <= cv <= v1) or not face.isPartOfDomain(cu, cv):
                continue
            candidate = _radius_or_inf(face, cu, cv, min_element)
            if candidate < r:
                u, v, r, moved = cu, cv, candidate, True
        if not moved:
            step = step / 2.0
    return r


def classify_face(face, name: str = "face") -> FaceInfo:
    """Kind, area, analytic data and smallest radius of one face."""
    kind = face_kind(face)
    surface = face.Surface
    info = {"name": name, "kind": kind, "area": float(face.Area),
            "smallest_radius": smallest_radius(face)}
    if kind == "plane":
        info.update(axis=_vec(face.normalAt(*_mid(face))), center=_vec(surface.Position))
    elif kind in ("cylinder", "sphere"):
        info.update(axis=_vec(surface.Axis), center=_vec(surface.Center), radius=float(surface.Radius))
    elif kind == "cone":
        info.update(axis=_vec(surface.Axis), center=_vec(surface.Apex),
                    radius=float(surface.Radius), semi_angle=float(surface.SemiAngle))
    elif kind == "torus":
        info.update(axis=_vec(surface.Axis), center=_vec(surface.Center),
                    radius=float(surface.MajorRadius), minor_radius=float(surface.MinorRadius))
    return FaceInfo(**info)


def classify_faces(shape) -> list[FaceInfo]:
    """FaceInfo for every face of `shape`, named Face1..FaceN as FreeCAD names them."""
    return [classify_face(face, f"Face{i + 1}") for i, face in enumerate(shape.Faces)]


def _mid(face) -> tuple[float, float]:
    u0, u1, v0, v1 = face.ParameterRange
    return 0.5 * (u0 + u1), 0.5 * (v0 + v1)
