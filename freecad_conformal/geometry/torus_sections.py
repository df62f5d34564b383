"""Plane ∩ torus in closed form, as B-spline curves within a stated tolerance.

OCC intersects a plane with a torus by numerical walking unless the plane is normal to the
axis or contains it (≈ 7 ms per plane on a fillet, most of a nut's section time). Here the
curve comes from the torus' own parametrisation. With e1 the unit part of the plane normal
n across the axis w (n = s·e1 + c·w) and k the plane's offset from the centre, a point
C + (R + r cos v)(cos u e1 + sin u e2) + r sin v w lies on the plane when

    r s cos u · cos v + r c · sin v = k − R s cos u,

solved for v at each u: v = atan2(c, s cos u) ± acos(g(u)). Solutions exist for x = cos u in
the interval where (R² − r²)s²x² − 2kRs x + k² − r²c² ≤ 0; its end points are the turning
points where the two branches meet. Parametrising u = m − h·cos τ clusters samples there and
makes both branches one smooth closed curve in τ. The exact points are interpolated by a
periodic B-spline, refined until its distance to both surfaces (closed form) is within
`FIT_TOLERANCE`.

A spindle torus (R < r, a domed head in a STEP file) has the same equation; its quadratic
opens downwards, so the plane meets it outside the roots, and its inner sheet lies across
the axis. OCC walks even its circles (planes square to the axis), which are given here.
"""
from __future__ import annotations

import math

import numpy as np

from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry.frames import cross
from freecad_conformal.tolerances import ROUNDING_SLACK

#: Largest distance (mm) of the fitted curve from the plane and from the torus. OCC's own
#: walked curves on the Pump_Nut fillets deviate by 2e-8 to 6e-8 (measured), so this is
#: OCC's accuracy, not a looser one.
FIT_TOLERANCE = 1e-7

#: Cases closer than this to a degenerate configuration (plane normal to the axis, two
#: loops touching, a branch touching itself) are left to OCC (returns None).
DEGENERATE = 1e-9

#: A plane whose normal leans less than this (rad) from a torus' axis is square to it: its
#: sections are circles (a lean of 1e-12 moves them by 1e-10 mm on a 100 mm torus). OCC
#: gives a ring torus' circles in closed form, but walks a spindle torus' (9 ms a plane on
#: the screw's domed head, 0.3 of its 0.5 s of layers).
SQUARE_TO_AXIS = 1e-12

#: Samples for a whole loop on the first try, the fewest for a stretch, and the most before
#: giving the case to OCC. On Pump_Nut's fillets no loop met the tolerance with 128 samples,
#: 82 % did with 256 and the rest with 512; a failed try predicts the count it needs from its
#: deviation (a cubic interpolant's error falls as the fourth power of the spacing).
FIRST_SAMPLES = 256
MIN_SAMPLES = 16
MAX_SAMPLES = 4096

#: Loops are scanned at this many τ samples to find the stretches inside a face's (u, v)
#: box, which is widened by `DOMAIN_MARGIN` (rad) so stretch ends fall outside the face.
DOMAIN_SAMPLES = 720
DOMAIN_MARGIN = 0.02


def torus_plane_curves(torus, normal: np.ndarray, height: float,
                       domain: tuple[float, float, float, float] | None = None) -> list | None:
    """B-spline curves of the plane n·p = height on the torus, near the (u, v) `domain`.

    Curves are periodic when a whole loop lies in the domain (or no domain is given);
    otherwise each stretch of a loop that passes through the domain becomes an open curve
    whose ends lie outside the domain, so a face's edges cut it strictly inside.
    Returns None for configurations OCC handles in closed form (plane normal to the axis or
    containing it) or that are degenerate (touching loops): the caller then asks OCC.
    """
    App, Part = import_freecad()
    centre = np.array(tuple(torus.Center))
    w = np.array(tuple(torus.Axis))
    w = w / np.linalg.norm(w)
    n = np.asarray(normal, dtype=float)
    R, r = float(torus.MajorRadius), float(torus.MinorRadius)
    c = float(n @ w)
    across = n - c * w
    s = float(np.linalg.norm(across))
    k = float(height - n @ centre)
    if R < r and s < SQUARE_TO_AXIS:
        return _spindle_circles(centre, w, R, r, c, k, App, Part)
    if s < 1e-6 or (abs(c) < 1e-12 and abs(k) < 1e-9) or abs(R - r) < DEGENERATE * r:
        return None  # OCC's analytic cases (circles) or a horn torus (its tube meets the axis)
    e1 = across / s
    e2 = cross(w, e1)
    loops = _loops_in_u(R, r, s, c, k)
    if loops is None:
        return None
    torus_shape = _TorusSection(centre, e1, e2, w, R, r, s, c, k, n, height)
    u_map = _u_map(torus, torus_shape)
    curves = []
    for kind, low, high in loops:
        scan = None if domain is None else _DomainScan(torus_shape, kind, low, high, domain, u_map)
        for branch in ((1,) if kind == "turning" else (1, -1)):
            stretches = [(0.0, 2 * math.pi)] if scan is None else scan.stretches(branch)
            for first, last in stretches:
                curve = _fit(torus_shape, kind, low, high, branch, first, last, App, Part)
                if curve is None:
                    return None
                curves.append(curve)
    return curves


class _TorusSection:
    """The plane and torus in the frame of the module docstring; maps τ to points."""

    def __init__(self, centre, e1, e2, w, R, r, s, c, k, n, height) -> None:
        self.centre, self.e1, self.e2, self.w = centre, e1, e2, w
        self.R, self.r, self.s, self.c, self.k = R, r, s, c, k
        self.n, self.height = n, height

    def uv(self, kind: str, low: float, high: float, branch: int, tau: np.ndarray):
        """(u, v) on one closed loop (turning) or one branch going around, at τ ∈ [0, 2π)."""
        tau, u, middle, swing = self.halves(kind, low, high, tau)
        sign = _turning_sign(tau) if kind == "turning" else np.full_like(tau, float(branch))
        return u, middle + sign * swing

    def halves(self, kind: str, low: float, high: float, tau: np.ndarray):
        """(τ wrapped to [0, 2π), u, v's middle, its swing) at τ: v = middle ± swing, both
        branches of a loop going around from one evaluation (`_DomainScan` takes u and the
        v halves in two steps, to stop after u where the loop misses the face)."""
        tau, u = self.u_at(kind, low, high, tau)
        return (tau, u, *self.v_halves(u))

    def v_halves(self, u: np.ndarray):
        """(v's middle, its swing) at u."""
        x = np.cos(u)
        R, r, s, c, k = self.R, self.r, self.s, self.c, self.k
        g = (k - R * s * x) / (r * np.sqrt((s * x) ** 2 + c * c))
        return np.arctan2(c, s * x), np.arccos(np.clip(g, -1.0, 1.0))

    @staticmethod
    def u_at(kind: str, low: float, high: float, tau: np.ndarray):
        """(τ wrapped to [0, 2π), u) at τ."""
        tau = np.mod(tau, 2 * math.pi)
        if kind == "turning":
            middle, half = 0.5 * (low + high), 0.5 * (high - low)
            return tau, middle - half * np.cos(tau)
        return tau, tau

    def points(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        radial = (self.R + self.r * np.cos(v))[:, None]
        return (self.centre + radial * (np.cos(u)[:, None] * self.e1 + np.sin(u)[:, None] * self.e2)
                + (self.r * np.sin(v))[:, None] * self.w)

    def deviation(self, points: np.ndarray) -> float:
        """Largest distance of `points` from the torus or the plane (closed form)."""
        rel = points - self.centre
        along = rel @ self.w
        radial = np.linalg.norm(rel - along[:, None] * self.w, axis=1)
        off_torus = np.abs(np.hypot(radial - self.R, along) - self.r)
        if self.R < self.r:
            # A spindle torus' inner sheet (R + r cos v < 0) lies across the axis: its
            # points are r from the core circle's opposite point.
            off_torus = np.minimum(off_torus, np.abs(np.hypot(radial + self.R, along) - self.r))
        off_plane = np.abs(points @ self.n - self.height)
        return float(max(off_torus.max(), off_plane.max()))


def _u_map(torus, section: _TorusSection) -> tuple[float, float]:
    """(offset, sign) with OCC's u = offset + sign·(our u): the frames differ by a turn about
    the axis, and an imported torus may have an indirect frame (u running the other way)."""
    App, _ = import_freecad()
    R, r = section.R, section.r

    def occ_u(angle: float) -> float:
        # A point on the outer equator: one on the core circle is equidistant from a whole
        # tube circle, and OCC's projection of it returns an arbitrary u.
        d = math.cos(angle) * section.e1 + math.sin(angle) * section.e2
        u, _ = torus.parameter(App.Vector(*(section.centre + (R + r) * d)))
        return float(u)

    offset = occ_u(0.0)
    turned = (occ_u(0.5) - offset) % (2 * math.pi)
    return offset, (1.0 if turned < math.pi else -1.0)


def _within(angle: np.ndarray, low: float, high: float) -> np.ndarray:
    if high - low >= 2 * math.pi - ROUNDING_SLACK:
        return np.ones(angle.shape, dtype=bool)
    return np.mod(angle - low, 2 * math.pi) <= (high - low)


def _turning_sign(tau: np.ndarray) -> np.ndarray:
    """v's branch along a turning loop: +swing out to the far turning point (τ ≤ π), then
    back along −swing."""
    return np.where(tau <= math.pi, 1.0, -1.0)


#: The τ samples every loop is scanned at, their cosines and a turning loop's branch signs
#: at them (read-only: shared by all scans; `_TorusSection.u_at` of them, once).
_DOMAIN_TAU = np.linspace(0.0, 2 * math.pi, DOMAIN_SAMPLES, endpoint=False)
_DOMAIN_COS = np.cos(_DOMAIN_TAU)
_DOMAIN_TURNING = _turning_sign(_DOMAIN_TAU)
for _samples in (_DOMAIN_TAU, _DOMAIN_COS, _DOMAIN_TURNING):
    _samples.setflags(write=False)
del _samples


class _DomainScan:
    """One loop scanned at `DOMAIN_SAMPLES` τ for the stretches inside a face's (u, v) box,
    widened by `DOMAIN_MARGIN` (rad) so stretch ends fall outside the face, on one shared
    array of samples. Both branches of a loop going around share its u samples and v's
    middle and swing (most loops of the bottle's and the nut's fillets turn, one branch)."""

    def __init__(self, section, kind, low, high, domain, u_map) -> None:
        u0, u1, self._v0, self._v1 = domain
        if kind == "turning":
            # u_at's values: the samples lie in [0, 2π), so wrapping leaves them as they are
            middle, half = 0.5 * (low + high), 0.5 * (high - low)
            u = middle - half * _DOMAIN_COS
        else:
            u = _DOMAIN_TAU
        self._u_inside = _within(u_map[0] + u_map[1] * u, u0 - DOMAIN_MARGIN, u1 + DOMAIN_MARGIN)
        if not self._u_inside.any():
            return      # the loop passes beside the face (half the bottle's scans): no v
        self._middle, self._swing = section.v_halves(u)
        self._turning = _DOMAIN_TURNING if kind == "turning" else None

    def stretches(self, branch: int) -> list[tuple[float, float]]:
        """τ intervals of the loop (`branch` of one going around) that pass through the
        domain (each padded beyond it)."""
        if not self._u_inside.any():
            return []
        sign = self._turning if self._turning is not None else float(branch)
        v = self._middle + sign * self._swing
        inside = self._u_inside & _within(v, self._v0 - DOMAIN_MARGIN, self._v1 + DOMAIN_MARGIN)
        if inside.all():
            return [(0.0, 2 * math.pi)]
        if not inside.any():
            return []
        step = 2 * math.pi / DOMAIN_SAMPLES
        start = int(np.argmin(inside))           # an outside sample: runs never wrap past it
        # The samples from `start` on, then those before, between two outside ones: runs
        # start and end where neighbours differ (np.roll and np.diff cost 3x as much).
        padded = np.zeros(DOMAIN_SAMPLES + 2, dtype=bool)
        padded[1:DOMAIN_SAMPLES + 1 - start] = inside[start:]
        padded[DOMAIN_SAMPLES + 1 - start:DOMAIN_SAMPLES + 1] = inside[:start]
        edges = np.flatnonzero(padded[1:] != padded[:-1])
        return [((start + first - 1) * step, (start + last) * step)
                for first, last in zip(edges[::2], edges[1::2])]


def _fit(section, kind, low, high, branch, first, last, App, Part):
    """A cubic B-spline through exact points on τ ∈ [first, last], refined to tolerance."""
    closed = bool(last - first >= 2 * math.pi - 1e-12)
    fraction = (last - first) / (2 * math.pi)
    count = max(MIN_SAMPLES, int(FIRST_SAMPLES * fraction))
    while count <= MAX_SAMPLES:
        tau = np.linspace(first, last, count, endpoint=not closed)
        points = section.points(*section.uv(kind, low, high, branch, tau))
        spline = Part.BSplineCurve()
        # Rows of three floats, not Vectors: the same curve, without 256 objects a try.
        spline.interpolate(Points=points.tolist(), PeriodicFlag=closed)
        knots = spline.getKnots()
        value = spline.value
        # tuple(Vector) reads the three coordinates in one call (a third of the check's time)
        check = np.array([tuple(value(0.5 * (a + b))) for a, b in zip(knots, knots[1:])])
        deviation = section.deviation(check)
        if deviation <= FIT_TOLERANCE:
            return spline
        count = int(count * min(8.0, max(2.0, 1.1 * (deviation / FIT_TOLERANCE) ** 0.25)))
    return None


def _loops_in_u(R: float, r: float, s: float, c: float, k: float):
    """Loops as ("turning", u1, u2) or ("around", 0, 2π) (two branches); None if degenerate."""
    if R < r:
        return _spindle_loops_in_u(R, r, s, c, k)
    root = r * math.sqrt(k * k + (R * R - r * r) * c * c)
    denominator = (R * R - r * r) * s
    a, b = (k * R - root) / denominator, (k * R + root) / denominator
    if b < -1.0 or a > 1.0:
        return []
    for end in (a, b):
        if abs(abs(end) - 1.0) < DEGENERATE or abs(b - a) < DEGENERATE:
            return None
    if a <= -1.0 and b >= 1.0:
        return [("around", 0.0, 2 * math.pi)]
    if b >= 1.0:
        return [("turning", -math.acos(a), math.acos(a))]
    if a <= -1.0:
        return [("turning", math.acos(b), 2 * math.pi - math.acos(b))]
    return [("turning", math.acos(b), math.acos(a)), ("turning", -math.acos(a), -math.acos(b))]


def _spindle_circles(centre: np.ndarray, w: np.ndarray, R: float, r: float, c: float,
                     k: float, App, Part) -> list | None:
    """The circles where a plane square to a spindle torus' axis (n = c·w, offset k from the
    centre) meets it: r·c·sin v = k at two v, each a circle of radius |R + r cos v| about
    the axis. None where the plane touches the tube or a circle shrinks onto the axis."""
    sine = k / (r * c)
    if abs(sine) >= 1.0 - DEGENERATE:
        return [] if abs(sine) > 1.0 + DEGENERATE else None
    circles = []
    for v in (math.asin(sine), math.pi - math.asin(sine)):
        radius = R + r * math.cos(v)
        if abs(radius) < DEGENERATE * r:
            return None
        middle = centre + r * math.sin(v) * w
        circles.append(Part.Circle(App.Vector(*middle), App.Vector(*w), abs(radius)))
    return circles


def _spindle_loops_in_u(R: float, r: float, s: float, c: float, k: float):
    """`_loops_in_u` of a spindle torus (R < r: a lemon inside an apple, as STEP files give
    for a domed head): the quadratic in x = cos u opens downwards, so the plane meets the
    surface outside its roots, not between them."""
    discriminant = k * k + (R * R - r * r) * c * c
    if abs(discriminant) < DEGENERATE * r * r:
        return None
    if discriminant < 0.0:
        return [("around", 0.0, 2 * math.pi)]       # no root: every u meets the plane
    root = r * math.sqrt(discriminant)
    denominator = (R * R - r * r) * s
    low, high = sorted(((k * R - root) / denominator, (k * R + root) / denominator))
    for end in (low, high):
        if abs(abs(end) - 1.0) < DEGENERATE or abs(high - low) < DEGENERATE:
            return None
    if high < -1.0 or low > 1.0:
        return [("around", 0.0, 2 * math.pi)]
    loops = []
    if low > -1.0:
        loops.append(("turning", math.acos(low), 2 * math.pi - math.acos(low)))
    if high < 1.0:
        loops.append(("turning", -math.acos(high), math.acos(high)))
    return loops
