"""Whether a point of a face's surface lies in the face: its (u, v) in the trimmed domain.

OCC's classifier (`Face.isInside`) takes about 0.5 ms a call; the face-by-face section asks
once per curve piece. The face's parameter domain is discretised once into a shapely
polygon and points are tested against it; only points too close to its boundary for the
discretisation to decide go to OCC.
"""
from __future__ import annotations

import math

import numpy as np
import shapely
from shapely.geometry import Polygon

from freecad_conformal.geometry.uv_projection import SurfaceProjector

#: Points per edge when discretising the face's boundary curves in (u, v): at least these,
#: evenly in parameter.
UV_POINTS_PER_EDGE = 48

#: FreeCAD's names of 2-D curves that are straight: two points describe them exactly.
STRAIGHT_2D = frozenset({"Line2d", "Line2dSegment"})

#: A point whose (u, v) neighbours this far away (a share of `domain_scale`) disagree
#: with it lies too near the discretised boundary: OCC decides.
UV_AMBIGUOUS = 1e-3

#: OCC's classification tolerance (mm) for those points.
CLASSIFY_TOLERANCE = 1e-7

#: Most a boundary curve's polygon strays from it in (u, v), as a share of the face's
#: parameter range (`domain_scale`): a quarter of the UV_AMBIGUOUS stencil, so that a point
#: the polygon places wrongly always has neighbours that disagree, and goes to OCC. With the evenly
#: spaced points alone, the middle of a 0.39 mm chord across a coil spring's 38 mm cut
#: edge was read as in the face where OCC has it outside (the layer went to the Boolean),
#: and so were most such chords across a plate's wavy hole (tests/geometry/test_face_cut).
UV_DEFLECTION = UV_AMBIGUOUS / 4.0

#: The range the stencil and the deflection are shares of: the face's shorter parameter
#: range, but not below its longer one over this. Shares of the longer range made the
#: stencil wide across a narrow face: a piece of the bottle's thread 0.005 outside its
#: face's v range of 0.83, and one of a fillet's cylinder 0.009 rad inside its u range of
#: 1.17 (its v range 45 mm), went to OCC (483 of its 15,443 points cut along X, 0.49 s;
#: CrankArm's plan: 991, 0.64 s). A face narrower than that keeps a wider stencil (more
#: points go to OCC) rather than a polygon too fine to build.
MAX_RANGE_RATIO = 64.0


class FaceDomain:
    """The trimmed (u, v) domain of one face, built on first use."""

    def __init__(self, face) -> None:
        self.face = face
        self.surface = face.Surface
        self._polygon = None
        #: the polygon's (u0, v0, u1, v1), read once: shapely's bounds cost ~10 µs a call,
        #: and a periodic face asks for them at every point (the bottle's fillets: 37,000)
        self._bounds: tuple = ()
        self._size = 1.0
        self._u_period = self.surface.UPeriod() if self.surface.isUPeriodic() else 0.0
        self._v_period = self.surface.VPeriod() if self.surface.isVPeriodic() else 0.0
        self._broken = False
        self._projector: SurfaceProjector | None = None

    def prepare(self) -> None:
        """Discretise the domain now (`contains` does it on first use otherwise)."""
        if self._polygon is None and not self._broken:
            try:
                self._polygon, self._size = _domain_polygon(self.face)
                self._bounds = tuple(self._polygon.bounds)
            except (ValueError, shapely.errors.ShapelyError):
                self._broken = True    # a boundary without curves on the face: ask OCC

    def contains(self, point) -> bool:
        """Whether the surface point (a FreeCAD Vector) lies in the face."""
        self.prepare()
        verdict = None if self._broken else self._verdict(point)
        return self._classified(point) if verdict is None else verdict

    def _verdict(self, point) -> bool | None:
        """The polygon's verdict on the surface point, None when it lies too near the
        discretised boundary for the polygon to decide."""
        u, v = self._parameter(point)
        step = UV_AMBIGUOUS * self._size
        ambiguous = False
        for u_copy in self._copies(u, 0, self._u_period):
            for v_copy in self._copies(v, 1, self._v_period):
                verdicts = shapely.contains_xy(
                    self._polygon, np.array([u_copy, u_copy - step, u_copy + step, u_copy, u_copy]),
                    np.array([v_copy, v_copy, v_copy, v_copy - step, v_copy + step]))
                if verdicts.all():
                    return True
                ambiguous = ambiguous or bool(verdicts.any())
        return None if ambiguous else False

    def _classified(self, point) -> bool:
        """OCC's classification of the surface point (about 0.5-1 ms)."""
        return bool(self.face.isInside(point, CLASSIFY_TOLERANCE, True))

    def _parameter(self, point) -> tuple[float, float]:
        """(u, v) of a surface point: Newton from a grid on B-spline surfaces, whose OCC
        projection is slow (`uv_projection`), OCC's own elsewhere."""
        if type(self.surface).__name__ != "BSplineSurface":
            return self.surface.parameter(point)
        if self._projector is None:
            self._projector = SurfaceProjector(self.surface)
        return self._projector.parameter(point)

    def _copies(self, value: float, axis: int, period: float) -> list[float]:
        """`value` and its copies a period apart that fall in the domain's range along
        `axis`: a face may span more than one period (a thread's crest on its cylinder winds
        round twice, u from 0.12 to 12.4), so a point of its second turn must not be
        folded onto the first."""
        if not period:
            return [value]
        low, high = self._bounds[axis], self._bounds[axis + 2]
        first = low + (value - low) % period
        copies = [first]
        # np.arange's values (first, first + period, then first + i·(its second − first)),
        # without building an array for the one or two a face holds.
        count = math.ceil((max(high, first) + 0.5 * period - first) / period)
        if count > 1:
            second = first + period
            step = second - first
            copies.extend([second] + [first + i * step for i in range(2, count)])
        return [c for c in copies if c <= high or c == first]


def _domain_polygon(face):
    """The face's parameter domain as a prepared shapely polygon, and its size."""
    rings = []
    outer = face.OuterWire
    u0, u1, v0, v1 = face.ParameterRange
    size = domain_scale(u1 - u0, v1 - v0)
    deflection = UV_DEFLECTION * size
    for wire in face.Wires:
        ring = []
        for edge in wire.OrderedEdges:
            found = face.curveOnSurface(edge)
            if found is None:
                raise ValueError("edge without a curve on the face")
            curve2d, a, b = found
            uv = _edge_points(curve2d, a, b, deflection)
            if edge.Orientation == "Reversed":
                uv.reverse()
            ring.extend(uv[:-1])
        rings.append((wire.isSame(outer), ring))
    shells = [ring for is_outer, ring in rings if is_outer]
    if not shells:
        raise ValueError("face without an outer wire")
    holes = [ring for is_outer, ring in rings if not is_outer]
    polygon = shapely.make_valid(Polygon(shells[0], holes))
    shapely.prepare(polygon)
    return polygon, max(size, 1e-12)


def _edge_points(curve2d, a: float, b: float, deflection: float) -> list[tuple[float, float]]:
    """(u, v) points along one boundary curve from parameter a to b: its ends where it is a
    straight line (the polygon is then exact: a gear's 400 flat flanks took 48 points an
    edge, 1.4 ms a face, 1.6 s of its plan choice), else at least UV_POINTS_PER_EDGE."""
    if type(curve2d).__name__ in STRAIGHT_2D:
        points = [curve2d.value(a), curve2d.value(b)]
    else:
        close = (curve2d.discretize(Deflection=deflection, First=a, Last=b)
                 if deflection > 0.0 else [])
        points = (close if len(close) > UV_POINTS_PER_EDGE
                  else [curve2d.value(t) for t in np.linspace(a, b, UV_POINTS_PER_EDGE)])
    return [(p.x, p.y) for p in points]


def domain_scale(u_range: float, v_range: float) -> float:
    """The length in (u, v) the stencil and the polygon's deflection are shares of: the
    shorter range, or the longer over MAX_RANGE_RATIO where the face is narrower."""
    return max(min(u_range, v_range), max(u_range, v_range) / MAX_RANGE_RATIO)
