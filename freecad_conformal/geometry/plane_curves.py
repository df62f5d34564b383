"""Where a plane meets a solid's edges and faces: crossing points and trimmed curve pieces.

Building blocks of the face-by-face section (`face_cut`). Every function answers None when
the configuration is not generic (an edge lying in the plane, a tangent crossing, a surface
OCC cannot intersect): the caller then leaves the layer to the Boolean.
"""
from __future__ import annotations

import math
from typing import Iterator

import numpy as np

from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry.spline_sections import spline_plane_curves
from freecad_conformal.geometry.torus_sections import torus_plane_curves
from freecad_conformal.tolerances import ROUNDING_SLACK

#: A vertex closer than this (mm) to the plane sends the layer to the Boolean: the plane
#: passes through an edge end, where curve pieces of several faces meet at one point.
VERTEX_CLEARANCE = 1e-6

#: A crossing point lies on an intersection curve when closer than this (mm). OCC's walked
#: curves are within ~1e-7 of their surfaces, analytic ones within 1e-12, but B-spline
#: edges of imported models sit up to 1.3e-4 mm off their faces (bottle.brep, measured).
ON_CURVE = 2e-4

#: |cos| of a circle edge's crossing above this is a near-tangent crossing: the two roots
#: merge and their order is ill-conditioned, so the layer goes to the Boolean.
TANGENT_COS = 1.0 - 1e-9

#: OCC reports an unbounded curve's parameter range as ±2e100.
UNBOUNDED = 1e99

#: (start, end, first crossing id, last crossing id); ids are None at a free curve end.
Span = tuple[float, float, "int | None", "int | None"]


#: FreeCAD's names of a straight edge's curve.
STRAIGHT_CURVES = ("Line", "LineSegment")


def curve_name(edge) -> str:
    """The type name of an edge's curve; "" for one FreeCAD cannot hand to Python (it raises
    for curve types it has no class for): such an edge is neither straight nor a circle."""
    try:
        return type(edge.Curve).__name__
    except (TypeError, RuntimeError):
        return ""


def edge_crosser(edge, n: np.ndarray):
    """What finds where one edge crosses the planes n·p = h: lines and circles in closed form
    (their heights along n read once, since a cutter's normal is fixed), other curves by OCC."""
    name = curve_name(edge)
    if name in STRAIGHT_CURVES:
        return LineCrosser(edge, n)
    if name == "Circle":
        return CircleCrosser(edge, n)
    return CurveCrosser(edge, n)


class LineCrosser:
    def __init__(self, edge, n: np.ndarray) -> None:
        first, last = edge.ParameterRange
        self.a = np.array(tuple(edge.valueAt(first)))
        self.b = np.array(tuple(edge.valueAt(last)))
        self.ha, self.hb = float(self.a @ n), float(self.b @ n)

    def at(self, height: float) -> list[np.ndarray] | None:
        """Crossing points at `height` (None: the edge lies in the plane)."""
        ha, hb = self.ha, self.hb
        if abs(hb - ha) < VERTEX_CLEARANCE:
            # Parallel to the plane: in it (the Boolean's case) or no crossing at all.
            return None if abs(height - ha) < VERTEX_CLEARANCE else []
        t = (height - ha) / (hb - ha)
        return [self.a + t * (self.b - self.a)] if 0.0 < t < 1.0 else []


class CircleCrosser:
    def __init__(self, edge, n: np.ndarray) -> None:
        circle = edge.Curve
        self.first, self.last = edge.ParameterRange
        self.centre = np.array(tuple(circle.Center))
        self.x = np.array(tuple(circle.XAxis))
        self.y = np.cross(np.array(tuple(circle.Axis)), self.x)
        self.radius = float(circle.Radius)
        p, q = self.radius * float(self.x @ n), self.radius * float(self.y @ n)
        self.amplitude, self.phase = math.hypot(p, q), math.atan2(q, p)
        self.centre_height = float(self.centre @ n)

    def extremes(self) -> list[tuple[float, bool]]:
        """(height, whether highest) of the circle's highest and lowest points along the
        normal that lie on the edge; none for a circle parallel to the cut."""
        if self.amplitude < VERTEX_CLEARANCE:
            return []
        found = []
        for theta, height, top in ((self.phase, self.centre_height + self.amplitude, True),
                                   (self.phase + math.pi, self.centre_height - self.amplitude,
                                    False)):
            if self.first + (theta - self.first) % (2 * math.pi) <= self.last:
                found.append((height, top))
        return found

    def at(self, height: float) -> list[np.ndarray] | None:
        """Crossing points at `height` (None: in the plane, or a near-tangent crossing)."""
        if self.amplitude < VERTEX_CLEARANCE:
            # The circle lies parallel to the cut: in it (the Boolean's case) or apart.
            return None if abs(height - self.centre_height) < VERTEX_CLEARANCE else []
        c = (height - self.centre_height) / self.amplitude
        if abs(c) >= TANGENT_COS:
            return None if abs(c) < 1.0 + ROUNDING_SLACK else []
        spread = math.acos(c)
        found = []
        for theta in (self.phase + spread, self.phase - spread):
            t = self.first + (theta - self.first) % (2 * math.pi)
            if t < self.last:
                found.append(self.centre + self.radius * (math.cos(t) * self.x + math.sin(t) * self.y))
        return found


class CurveCrosser:
    def __init__(self, edge, n: np.ndarray) -> None:
        self.curve = edge.Curve
        self.first, self.last = edge.ParameterRange
        self.n = n

    def at(self, height: float) -> list[np.ndarray] | None:
        """Crossing points at `height` (None: OCC failed, or the curve runs in the plane)."""
        App, Part = import_freecad()
        curve, first, last = self.curve, self.first, self.last
        plane = Part.Plane(App.Vector(*(height * self.n)), App.Vector(*self.n))
        try:
            hits, segments = curve.intersectCS(plane)
        except Part.OCCError:
            return None
        if segments:
            return None
        found = []
        for hit in hits:
            point = np.array([hit.X, hit.Y, hit.Z])
            t = curve.parameter(App.Vector(*point))
            if curve.isPeriodic():
                t = first + (t - first) % curve.period()
            if first < t < last:
                found.append(point)
        return found


def surface_curves(surface, parameter_range, plane, n: np.ndarray, height: float) -> list | None:
    """The plane's intersection curves with a face's whole surface (None: OCC failed);
    `parameter_range` is the face's (u0, u1, v0, v1). `surface` may be a torus read from a
    surface of revolution (`revolved_torus.RevolvedTorus`)."""
    kind = type(surface).__name__
    if kind in ("Toroid", "RevolvedTorus"):
        domain = surface.domain(parameter_range) if kind == "RevolvedTorus" else parameter_range
        curves = torus_plane_curves(surface, n, height, domain)
        if curves is not None:
            return curves
    if kind == "Sphere":
        return sphere_plane_circle(surface, n, height)
    if kind == "BSplineSurface":
        curves = spline_plane_curves(surface, n, height, parameter_range)
        if curves is not None:
            return curves
    try:
        return list(surface.intersectSS(plane))
    except Exception:  # noqa: BLE001 - OCC raises bare Standard_Failure types here
        return None


#: A plane within this fraction of a sphere's radius of touching it is a tangent case,
#: left to the Boolean.
TANGENT_SLACK = 1e-6


def sphere_plane_circle(sphere, n: np.ndarray, height: float) -> list | None:
    """The plane n·p = height ∩ a sphere as one whole circle ([] if they miss, None if the
    plane touches it). OCC's own answer is split into two arcs at the sphere's seam on
    some planes, and an arc end that is no crossing point made the layer fall back: 14 of
    the bottle's layers along X."""
    App, Part = import_freecad()
    centre = np.array(tuple(sphere.Center))
    offset = height - float(centre @ n)
    radius_squared = sphere.Radius ** 2 - offset ** 2
    if radius_squared <= 0.0:
        return [] if -radius_squared > (TANGENT_SLACK * sphere.Radius) ** 2 else None
    radius = math.sqrt(radius_squared)
    if radius < TANGENT_SLACK * sphere.Radius:
        return None
    return [Part.Circle(App.Vector(*(centre + offset * n)), App.Vector(*n), radius)]



def finite(parameter: float) -> bool:
    return abs(parameter) < UNBOUNDED


def point_gap(curve, t0: float, t1: float) -> float:
    """Distance (mm) between the curve's points at two parameters."""
    return float((curve.value(t0) - curve.value(t1)).Length)


def curve_end(curve, t: float) -> bool:
    """Whether parameter `t` is at an end of an open, bounded curve (within ON_CURVE)."""
    lo, hi = curve.FirstParameter, curve.LastParameter
    if curve.isPeriodic() or not (finite(lo) and finite(hi)) or closed_piece(curve, lo, hi):
        return False
    return point_gap(curve, t, lo) < ON_CURVE or point_gap(curve, t, hi) < ON_CURVE


def closed_piece(curve, start: float, end: float) -> bool:
    return finite(start) and finite(end) and point_gap(curve, start, end) < ON_CURVE


def span_middle(curve, start: float, end: float):
    """The curve's point halfway through the span (start, end) in parameter. `curve_spans`
    runs a closed curve's last span past LastParameter; a non-periodic parametrisation
    (a B-spline fitted through a closed section) is not read there but extrapolated, so the
    middle is taken back by one turn. Read at the extrapolated point, the fan hub's span
    across its section's start, outside the face, was kept as inside: 21 of its layers went
    to the Boolean (1.1 s)."""
    middle = 0.5 * (start + end)
    lo, hi = curve.FirstParameter, curve.LastParameter
    if middle > hi and not curve.isPeriodic():
        middle -= hi - lo
    return curve.value(middle)


def curve_spans(curve, stops: list[tuple[float, int]]) -> Iterator[Span]:
    """Pieces of `curve` between its stops (parameter, crossing id), sorted by parameter.

    A closed curve is cut cyclically; an open one also yields its free ends (ids None),
    except where a stop sits on the end itself (a curve ending on the face's boundary).
    """
    lo, hi = curve.FirstParameter, curve.LastParameter
    bounded = finite(lo) and finite(hi)
    if curve.isPeriodic():
        hi = lo + curve.period()
        closed = True
    else:
        closed = bounded and point_gap(curve, lo, hi) < ON_CURVE
    if not stops:
        if bounded:
            yield lo, hi, None, None
        return
    if closed:
        period = hi - lo
        ordered = sorted((lo + (t - lo) % period, pid) for t, pid in stops)
        following = ordered[1:] + [(ordered[0][0] + period, ordered[0][1])]
        for (t0, p0), (t1, p1) in zip(ordered, following):
            yield t0, t1, p0, p1
        return
    for (t0, p0), (t1, p1) in zip(stops, stops[1:]):
        yield t0, t1, p0, p1
    if finite(lo) and point_gap(curve, lo, stops[0][0]) > ON_CURVE:
        yield lo, stops[0][0], None, stops[0][1]
    if finite(hi) and point_gap(curve, stops[-1][0], hi) > ON_CURVE:
        yield stops[-1][0], hi, stops[-1][1], None
