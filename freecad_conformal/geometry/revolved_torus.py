"""A surface of revolution of a circle about an axis in the circle's plane is a torus: read
as one, a plane meets it in closed form (`torus_sections.py`).

CAD makes such faces wherever a round profile turns about an axis: a pipe swept along an
arc (FreeCAD's `makePipeShell`), a revolved sketch with an arc in it, a STEP surface of
revolution. OCC walks a plane through them (14 ms a plane on a pipe elbow's bend: 22 of
its 25 s of 3-D layers); read as tori they take the closed form (the elbow's layers: 11 s).
"""
from __future__ import annotations

import math

import numpy as np

from freecad_conformal.geometry.frames import unit

#: The circle's plane holds the axis when its normal is square to the axis within this
#: (cosine) and its centre off the axis' plane by less than `IN_PLANE`: then the surface is
#: a torus to OCC's own accuracy. Anything further off is left to OCC's walking (the
#: closed form would measure its fit against a torus the face is not).
SQUARE_COS = 1e-12
IN_PLANE = 1e-9


class RevolvedTorus:
    """A surface of revolution of a circle, as the torus it is: the `Center`, `Axis`,
    `MajorRadius` and `MinorRadius` a torus has, and the surface's own (u, v) through
    `parameter`; `domain` turns a face's (u, v) box into the torus' (u, v) box, the v of
    the torus (the angle from the outer equator towards the axis) being the circle's
    parameter turned by `v_offset` and run by `v_sign`."""

    def __init__(self, surface, centre: np.ndarray, axis: np.ndarray, major: float,
                 minor: float, v_offset: float, v_sign: float) -> None:
        self.surface = surface
        self.Center, self.Axis = centre, axis
        self.MajorRadius, self.MinorRadius = major, minor
        self.v_offset, self.v_sign = v_offset, v_sign

    def parameter(self, point):
        """The surface's (u, v) of a point (u, the turn about the axis, is the torus' u up
        to an offset and sense `torus_sections._u_map` reads from here)."""
        return self.surface.parameter(point)

    def domain(self, box: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
        """A face's (u0, u1, v0, v1) on the surface as the torus' (u, v) box."""
        u0, u1, v0, v1 = box
        ends = sorted(self.v_offset + self.v_sign * v for v in (v0, v1))
        return u0, u1, ends[0], ends[1]

    def intersectSS(self, plane):  # noqa: N802 - the name of OCC's call it stands in for
        return self.surface.intersectSS(plane)


def revolved_torus(surface) -> RevolvedTorus | None:
    """`surface` (a SurfaceOfRevolution) as a torus, None unless it revolves a whole or
    partial circle about an axis in the circle's plane."""
    try:
        basis = surface.BasisCurve
    except (AttributeError, RuntimeError, TypeError):
        return None
    if type(basis).__name__ == "ArcOfCircle":
        basis = basis.Circle    # a trimmed circle keeps its circle's parameter
    if type(basis).__name__ != "Circle":
        return None
    w = unit(tuple(surface.Direction))
    on_axis = np.array(tuple(surface.Location))
    circle_centre = np.array(tuple(basis.Center))
    normal = unit(tuple(basis.Axis))
    if abs(float(normal @ w)) > SQUARE_COS or abs(float((circle_centre - on_axis) @ normal)) > IN_PLANE:
        return None
    offset = circle_centre - on_axis
    along = float(offset @ w)
    radial = offset - along * w
    major = float(np.linalg.norm(radial))
    minor = float(basis.Radius)
    if major <= minor:
        return None     # a spindle torus or a sphere: left to OCC (not tried as tori)
    outward = radial / major
    x_axis, y_axis = unit(tuple(basis.XAxis)), unit(tuple(basis.YAxis))
    # The circle's point at t is minor·(cos t X + sin t Y) from its centre, the torus' at v
    # minor·(cos v outward + sin v w): X sits at v = α, and Y a quarter turn on (v = α + t)
    # or back (v = α − t).
    alpha = math.atan2(float(x_axis @ w), float(x_axis @ outward))
    quarter = -math.sin(alpha) * outward + math.cos(alpha) * w
    sign = 1.0 if float(y_axis @ quarter) > 0.0 else -1.0
    return RevolvedTorus(surface, on_axis + along * w, w, major, minor, alpha, sign)

