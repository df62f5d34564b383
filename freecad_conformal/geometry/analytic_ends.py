"""A face's exact end along a direction in closed form, where its shape allows one.

`sections.extent_along` asks OCC's extrema for the distance from a far plane to each face
that may hold the end (0.5 ms a face: 0.1 s of Pump_Nut's 0.8 s plan choice). For a plane,
a cylinder or a cone no interior point is a strict local maximum of the height: along a
ruling the height is linear, so from any interior point it rises, or stays level, all the
way to the boundary. The face's end is then its boundary's, and each boundary edge that is
a line or a conic has its end in closed form: the highest of its two ends and the point
where its height's derivative vanishes, when that lies on the edge. Any other face (a
sphere's or a torus' top may lie inside the face) or edge (a B-spline) returns None, and
the caller asks OCC.
"""
from __future__ import annotations

import math

import numpy as np

from freecad_conformal.geometry.plane_curves import STRAIGHT_CURVES, curve_name

#: Faces whose height along any direction has no strict interior maximum (ruled, with
#: the height linear along each ruling).
RULED_SURFACES = ("Plane", "Cylinder", "Cone")


def face_top(face, up: np.ndarray) -> float | None:
    """Highest value of p·`up` over the face (unit `up`), None unless it has a closed form
    (see the module docstring)."""
    if type(face.Surface).__name__ not in RULED_SURFACES:
        return None
    top = -math.inf
    for edge in face.Edges:
        found = edge_top(edge, up)
        if found is None:
            return None
        top = max(top, found)
    return top if math.isfinite(top) else None


def edge_top(edge, up: np.ndarray) -> float | None:
    """Highest value of p·`up` over the edge, None unless it is a line or a conic."""
    if edge.Degenerated:
        return float(np.array(tuple(edge.Vertexes[0].Point)) @ up)
    name = curve_name(edge)
    first, last = edge.ParameterRange
    where = [first, last]
    if name not in STRAIGHT_CURVES:
        critical = _critical_parameter(name, edge.Curve, up, first, last)
        if critical is False:
            return None
        if critical is not None:
            where.append(critical)
    return max(float(np.array(tuple(edge.valueAt(t))) @ up) for t in where)


def _critical_parameter(name: str, curve, up: np.ndarray, first: float, last: float):
    """The parameter in [first, last] where the conic's height along `up` is highest (or,
    for a hyperbola or parabola, stationary), None when there is none there, False for a
    curve without a closed form. OCC's parametrisations: O + a·cos t·X + b·sin t·Y
    (circle, a = b; ellipse), O + a·cosh t·X + b·sinh t·Y (hyperbola), O + t²/(4f)·X + t·Y
    (parabola)."""
    if name not in ("Circle", "Ellipse", "Hyperbola", "Parabola"):
        return False
    x = float(np.array(tuple(curve.XAxis)) @ up)
    y = float(np.array(tuple(curve.YAxis)) @ up)
    if name == "Parabola":
        # h(t) = x t²/(4f) + y t: stationary at t = −2 f y / x (a minimum when x > 0,
        # which the ends then bound from above).
        if x == 0.0:
            return None
        t = -2.0 * float(curve.Focal) * y / x
    elif name == "Hyperbola":
        # h(t) = a x cosh t + b y sinh t: h' = 0 where tanh t = −b y / (a x).
        p, q = float(curve.MajorRadius) * x, float(curve.MinorRadius) * y
        if abs(q) >= abs(p):
            return None
        t = math.atanh(-q / p)
    else:
        a = float(curve.Radius) if name == "Circle" else float(curve.MajorRadius)
        b = a if name == "Circle" else float(curve.MinorRadius)
        # h(t) = a x cos t + b y sin t peaks at t = atan2(b y, a x), on the edge's turn.
        t = math.atan2(b * y, a * x)
        t = first + (t - first) % (2 * math.pi)
    return t if first <= t <= last else None
