"""OCC's exact surface normals where meshes need them: a planar face's normal, and the
normals of a curved face at its triangulation's nodes."""
from __future__ import annotations

import numpy as np

from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry.frames import points_array
from freecad_conformal.geometry.rows import find_rows, unique_rows
from freecad_conformal.geometry.shape_cache import ShapeCache
from freecad_conformal.tolerances import ZERO_LENGTH

#: Tessellation points and the triangulation's UV nodes are matched by position rounded to
#: this (mm): far below the mesh spacing, far above the 1e-12 scatter of one evaluation.
NODE_MATCH = 1e-6

#: A node normal shorter than this is missing (OCC has none at poles and apexes).
MISSING_NORMAL = 1e-9


#: Planar faces' normals (None: not planar), by face identity and orientation: the overhang
#: scans read every face's in each of 30-odd directions, and a cut leaves most faces of a
#: piece as they were (Pump_Nut: 1,918 reads of 0.03 ms each in its plan choice).
_NORMALS: ShapeCache = ShapeCache(limit=16384, oriented=True)


#: A free-form surface (B-spline, Bézier) lying within this (mm) of a plane is that plane:
#: exporters and lofts write planes so (an oblique prism lofted through squares has four
#: planar B-spline sides). Read as curved, the side a part stands on counted as overhang,
#: so no orientation on it was ever offered. Far below any modelling tolerance (1e-4 mm
#: is STEP's usual), far above a plane's own B-spline rounding.
FREEFORM_PLANE = 1e-6
#: Surfaces that may be planes without saying so.
FREEFORM_SURFACES = frozenset({"BSplineSurface", "BezierSurface"})


def plane_normal(face) -> np.ndarray | None:
    """The outward unit normal of a planar face (read-only), None for any other surface.
    A B-spline or Bézier surface that is a plane (`FREEFORM_PLANE`) counts as one."""
    return _NORMALS.get((face,), lambda: _plane_normal(face))


def _plane_normal(face) -> np.ndarray | None:
    kind = type(face.Surface).__name__
    if kind != "Plane" and not (kind in FREEFORM_SURFACES and face.Surface.isPlanar(FREEFORM_PLANE)):
        return None
    u0, u1, v0, v1 = face.ParameterRange
    n = face.normalAt(0.5 * (u0 + u1), 0.5 * (v0 + v1))
    normal = np.array([n.x, n.y, n.z])
    normal.flags.writeable = False     # shared by every reader of this face
    return normal


def node_normals(face, points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Outward unit normals (face orientation applied) at the face's tessellation `points`.

    On cylinders, cones, spheres and tori, in closed form at the points (`_closed_form`).
    On other surfaces, read at the triangulation's own UV nodes through the surface
    (Surface.normal is ~60x cheaper than Face.normalAt, and no point has to be projected
    back with Surface.parameter); the nodes are matched to the points by position. Where
    the surface has no normal (a sphere's pole, a cone's apex) a node takes the mean of the
    flat normals of its `triangles`, oriented as OCC's around it."""
    closed = _closed_form(face, points)
    if closed is not None:
        return _fill_missing(closed, points, triangles)
    surface = face.Surface
    uv = face.getUVNodes()
    normals = np.array([_normal_or_zero(surface, u, v) for u, v in uv]).reshape(-1, 3)
    if face.Orientation == "Reversed":
        normals = -normals
    value = surface.value
    nodes = np.array([(p.x, p.y, p.z) for p in (value(u, v) for u, v in uv)]).reshape(-1, 3)
    # Each point takes the first node at its position (a seam's two nodes share one).
    node_keys = _position_keys(nodes)
    first, _ = unique_rows(node_keys)
    at = find_rows(node_keys[first], _position_keys(points))
    known = at >= 0
    result = np.zeros((len(points), 3))
    result[known] = normals[first[at[known]]]
    missed = np.flatnonzero(~known).tolist()
    if missed:
        # Nodes on edges: BRepMesh puts them on the edge's 3D curve and their UV on its
        # pcurve, which lie up to the edge's tolerance apart (2.7e-5 mm on the screw thread,
        # a tenth of its nodes): the node is the nearest UV node within that. Projecting
        # each back (Surface.parameter) cost 0.6 ms a node, 0.6 s a turned copy of it.
        reach = max(NODE_MATCH, EDGE_NODE_SLACK * max((e.Tolerance for e in face.Edges), default=0.0))
        nearest, distance = _nearest(points[missed], nodes)
        for i, k, gap in zip(missed, nearest, distance):
            if gap <= reach:
                result[i] = normals[k]
            else:  # not one of the triangulation's nodes: ask exactly
                result[i] = tuple(face.normalAt(*surface.parameter(_vector(points[i]))))
    return _fill_missing(result, points, triangles)


def _closed_form(face, points: np.ndarray) -> np.ndarray | None:
    """Normals of a quadric or torus at `points` from its axis and radii, oriented as OCC's
    (checked at one point of the face, which also settles a left-handed frame); None for
    other surfaces, or where that point has no normal. Nodes are points of the surface (or
    of an edge within its tolerance): no (u, v) is read back, which cost two OCC calls a
    node (Pump_Nut's choice: 0.04 s of 0.5)."""
    surface = face.Surface
    kind = type(surface).__name__
    if kind not in _CLOSED_FORMS or not len(points):
        return None
    if kind == "Toroid" and float(surface.MajorRadius) <= float(surface.MinorRadius):
        return None   # a spindle torus: a point near the axis lies on both of its sheets
    normals_at = _CLOSED_FORMS[kind]
    centre, axis = points_array([surface.Center, getattr(surface, "Axis", (0.0, 0.0, 1.0))])
    u0, u1, v0, v1 = face.ParameterRange
    u, v = 0.5 * (u0 + u1), 0.5 * (v0 + v1)
    reference = np.array(_normal_or_zero(surface, u, v))
    here = normals_at(surface, points_array([surface.value(u, v)]) - centre, axis)[0]
    agree = float(reference @ here)
    if abs(agree) < 1.0 - CLOSED_FORM_CHECK:
        return None           # no normal there (a pole, an apex), or not the surface we think
    sign = (1.0 if agree > 0 else -1.0) * (-1.0 if face.Orientation == "Reversed" else 1.0)
    return sign * normals_at(surface, points - centre, axis)


#: The closed-form normal and OCC's at the check point agree to this (1 - |cos|).
CLOSED_FORM_CHECK = 1e-9


def _across(offsets: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """Each offset's part across the axis."""
    return offsets - np.outer(offsets @ axis, axis)


def _unit_rows(vectors: np.ndarray) -> np.ndarray:
    """Rows scaled to unit length; zero rows (no normal: a pole, an apex) stay zero."""
    length = np.linalg.norm(vectors, axis=1)
    safe = length > MISSING_NORMAL
    out = np.zeros_like(vectors)
    out[safe] = vectors[safe] / length[safe, None]
    return out


def _cylinder_normals(surface, offsets: np.ndarray, axis: np.ndarray) -> np.ndarray:
    return _unit_rows(_across(offsets, axis))


def _sphere_normals(surface, offsets: np.ndarray, axis: np.ndarray) -> np.ndarray:
    return _unit_rows(offsets)


def _cone_normals(surface, offsets: np.ndarray, axis: np.ndarray) -> np.ndarray:
    # OCC's cone: P = C + (R + v sin α) e_r(u) + v cos α A, so du x dv lies along
    # cos α e_r - sin α A, scaled by R + v sin α (negative on the far nappe).
    alpha = float(surface.SemiAngle)
    v = (offsets @ axis) / np.cos(alpha)
    side = np.sign(float(surface.Radius) + v * np.sin(alpha))
    radial = _unit_rows(_across(offsets, axis))
    return _unit_rows(np.cos(alpha) * radial - (side * np.sin(alpha))[:, None] * axis)


def _torus_normals(surface, offsets: np.ndarray, axis: np.ndarray) -> np.ndarray:
    tube_centre = float(surface.MajorRadius) * _unit_rows(_across(offsets, axis))
    return _unit_rows(offsets - tube_centre)


_CLOSED_FORMS = {"Cylinder": _cylinder_normals, "Sphere": _sphere_normals,
                 "Cone": _cone_normals, "Toroid": _torus_normals}


#: A node may lie this many times its edge's tolerance from its UV node's surface point.
EDGE_NODE_SLACK = 2.0
#: Points per block of the nearest-node search: a block's distances are block x nodes
#: floats (13 MB against a 26,000-node blade face).
NEAREST_BLOCK = 64


def _nearest(points: np.ndarray, nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each point, the index of the nearest of `nodes` and its distance."""
    index = np.empty(len(points), dtype=int)
    distance = np.empty(len(points))
    lengths = (nodes ** 2).sum(axis=1)
    for start in range(0, len(points), NEAREST_BLOCK):
        block = points[start:start + NEAREST_BLOCK]
        squared = lengths[None, :] - 2.0 * block @ nodes.T
        best = squared.argmin(axis=1)
        index[start:start + len(block)] = best
        distance[start:start + len(block)] = np.linalg.norm(nodes[best] - block, axis=1)
    return index, distance


def _fill_missing(normals: np.ndarray, points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    length = np.linalg.norm(normals, axis=1)
    bad = length < MISSING_NORMAL
    normals[~bad] /= length[~bad, None]
    if bad.any() and len(triangles):
        a, b, c = (points[triangles[:, k]] for k in range(3))
        flat = np.cross(b - a, c - a)
        flat /= np.maximum(np.linalg.norm(flat, axis=1), 1e-300)[:, None]
        sign = np.sign(np.einsum("ij,ij->i", flat, normals[triangles].sum(axis=1)))
        oriented = flat * np.where(sign == 0, 1.0, sign)[:, None]
        for node in np.nonzero(bad)[0]:
            mean = oriented[np.any(triangles == node, axis=1)].sum(axis=0)
            normals[node] = mean / max(np.linalg.norm(mean), ZERO_LENGTH)
    return normals


def _position_keys(points: np.ndarray) -> np.ndarray:
    return np.round(points / NODE_MATCH).astype(np.int64).reshape(-1, 3)


def _normal_or_zero(surface, u: float, v: float) -> tuple[float, float, float]:
    """The surface's normal at (u, v); zero where OCC has none (poles, apexes)."""
    try:
        n = surface.normal(u, v)
    except Exception:  # noqa: BLE001 - OCC raises bare Standard_Failure types here
        return 0.0, 0.0, 0.0
    return n.x, n.y, n.z


def _vector(point: np.ndarray):
    App, _ = import_freecad()
    return App.Vector(*(float(c) for c in point))
