"""Plane ∩ B-spline surface in closed form across a one-span direction of degree 1 or 2.

OCC intersects a plane with a B-spline surface by numerical walking: 5–9 ms a plane on the
fan's lofted blades, 58 ms on a modelled thread's ruled flanks, and its walk misses short
pieces (a flank crossed along its axis: 12 of 20). Many B-spline faces are swept or lofted,
and across one parameter (t) they are a single Bézier span of degree 1 (ruled: a thread's
flanks, the bottle's blends) or 2 (a loft through three sections: the fan's blades,
CrankArm's arm), whatever they are along the other (s). Written homogeneously, with
λ = (t − t_a)/(t_b − t_a) and B_j the Bernstein polynomials,

    S = Σ_j B_j(λ) A_j(s) / Σ_j B_j(λ) W_j(s),  A_j = Σ_i N_i(s) w_ij P_ij,  W_j = Σ_i N_i(s) w_ij,

so the plane n·p = h holds where Σ_j B_j(λ) g_j(s) = 0 with g_j = n·A_j − h W_j: at each s a
polynomial of degree ≤ 2 in λ. Degree 1: λ = g0 / (g0 − g1), one branch over s. Degree 2:
λ = g0 / ((g0 − g1) ± √E), E = g1² − g0 g2, two roots that meet where E = 0 (turning points
in s); s = m − w·cos τ between two of them makes both one smooth loop in τ (as
`torus_sections.py` does for the torus). The exact points are interpolated by a cubic
B-spline in τ, refined until it is within `FIT_TOLERANCE` of the exact curve everywhere
between samples. Curves are the stretches that pass through the face's (s, t) box widened
by a margin, so that a face's edges cut them strictly inside (as the torus' are), or that
end exactly on the surface's boundary where the box reaches it. Where every ruling of a
degree-1 span is parallel to the plane (g0 ≡ g1: a loft across polygons in such planes, a
twisted prism along its axis; an extrusion along the plane), the plane holds whole rulings
at the zeros of g0 and meets nothing else: each is a straight line across the box (OCC
walked them at 1.3 ms a plane and face, 1.8 s of a twisted prism's 4.1 s plan). Anything
not generic (a plane holding some rulings but crossing others, a near-tangent plane, a
turning point the scan may have missed) returns None, and the caller asks OCC.
"""
from __future__ import annotations

import math

import numpy as np

from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry.bspline_numeric import (PowerPieces, bracketed_zeros,
                                                        curve_points)

#: Largest distance (mm) of a fitted curve from the exact intersection curve, as for the
#: torus: OCC's own walked curves stray 2e-8 to 2.4e-6 from their surfaces.
FIT_TOLERANCE = 1e-7

#: Samples of s scanned for the turning points and the stretches inside the face's box.
SCAN_SAMPLES = 1024

#: The face's box is widened by this share of its extent in each parameter for the
#: stretches (their ends then lie outside the face), and the roots are evaluated over twice
#: that, so that a stretch ending at the scanned window's edge ends outside the face.
DOMAIN_MARGIN = 0.01

#: Sub-samples between a stretch's last sample inside the widened box and the next one
#: outside, where its end is placed; also those put where λ passes over the whole box
#: between two samples (a thread's flank crossing a thin face), for `FILL_ROUNDS` rounds.
END_GRID = 16
FILL_ROUNDS = 3
#: ... where λ on both sides lies within this of the surface's λ range (farther, it ran off
#: to a pole between them: the fan's 1,232 such pairs held no stretch).
FILL_REACH = 1000.0

#: τ offset (rad) of the + root's end sample from the − root's where the two do not meet.
JUNCTION = 1e-9

#: A stretch's end placed on a λ target (the surface's boundary) lies within this of it;
#: else λ jumped there (a root running off at a degenerate row of poles) and the stretch
#: ends at its last point inside.
BOUNDARY_SLACK = 1e-9

#: E (relative to its largest value over the scan) this close to zero at a local extremum
#: is a near-tangent plane; an extremum on the far side of zero within `HIDDEN_BEND`
#: second differences of it may cross zero between samples (a loop narrower than a
#: sample, two turning points the scan cannot see). Both go to OCC.
TANGENT_SHARE = 1e-9
HIDDEN_BEND = 0.5

#: Degree 1: g0 − g1 this small (relative to the g's) where g0 changes sign is a ruling
#: (nearly) in the plane: the curve runs along t there, which λ(s) cannot follow.
RULING_SHARE = 1e-6

#: Sample points farther than this (mm) from the plane mean a root was taken where there
#: is none (a turning point missed: E clamped at zero); OCC decides.
PLANE_SLACK = 1e-8

#: Samples of a stretch on the first fitting try (degree 2: per 2π of τ), the fewest, and
#: the most before the case goes to OCC.
FIRST_SAMPLES = 128
MIN_SAMPLES = 16
MAX_SAMPLES = 8192
#: Samples closer than this share of the stretch are one (a knot's τ on a uniform sample).
SAME_SAMPLE = 1e-6
#: Where the fit strays, the intervals beyond this share of the tolerance are split too
#: (each try costs a fit), into at most `MAX_SPLIT`.
SPLIT_SHARE = 0.125
MAX_SPLIT = 16
#: A try whose largest deviation, above `FAIL_FLOOR` tolerances, is not `FAIL_RATIO` times
#: below the last one's gives up (a smooth curve's falls about sixteen-fold as the samples
#: double; near the tolerance an interval may stray a little as the interpolant changes),
#: as does the try after `MAX_TRIES`.
FAIL_RATIO = 3.0
FAIL_FLOOR = 16.0
MAX_TRIES = 12


def spline_plane_curves(surface, normal: np.ndarray, height: float,
                        domain: tuple[float, float, float, float]) -> list | None:
    """B-spline curves of the plane n·p = `height` on a B-spline `surface`, near the face's
    (u, v) `domain`; None when the surface has no one-span direction of degree ≤ 2 or the
    configuration is not generic (the caller then asks OCC)."""
    form = _form_of(surface, domain)
    if form is None:
        return None
    _, Part = import_freecad()
    curves = []
    # Once for the whole cut, not in each evaluation below (35,000 entries a fan's plan:
    # 0.2 s): λ = g0 / (g0 − g1) and the roots divide by zero or take NaN where the plane
    # meets a ruling or runs past a turning point, and those samples are read as such.
    with np.errstate(divide="ignore", invalid="ignore"):
        for found in form.stretches(np.asarray(normal, dtype=float), float(height)):
            if found is None:
                return None
            curve = found.curve(Part) if isinstance(found, _Ruling) else _fit(*found, Part)
            if curve is None:
                return None
            curves.append(curve)
    return curves


#: Forms by (surface object, domain): a face cutter keeps its faces' surfaces and cuts each
#: at many heights, so the poles are read and the scan evaluated once. The surface is kept
#: with its form, so its id cannot be reused meanwhile. Forms hold no state from one plane
#: to the next: a section is the same bits whichever process cut which plane.
_FORMS: dict = {}
FORM_CACHE = 512


def _form_of(surface, domain) -> "_Form | None":
    key = (id(surface), tuple(float(c) for c in domain))
    found = _FORMS.get(key)
    if found is None:
        if len(_FORMS) >= FORM_CACHE:
            _FORMS.pop(next(iter(_FORMS)))
        found = _FORMS[key] = (surface, _Form.of(surface, domain))
    return found[1]


class _Form:
    """The surface as s (any B-spline direction) by λ (one Bézier span of degree q = 1, 2),
    with the face's box in (s, λ): (widened, evaluated) windows for each."""

    def __init__(self, knots, degree, weighted, weights, t_range, s_window, t_window) -> None:
        self.knots, self.degree = knots, degree
        self.q = weights.shape[1] - 1
        self.t_range = t_range
        self.s_window, self.t_window = s_window, t_window
        # A_j and W_j together, one polynomial per span
        self._along = PowerPieces(knots, degree, np.concatenate(
            (weighted.reshape(len(weighted), -1), weights), axis=1))
        s = np.linspace(*s_window[1], SCAN_SAMPLES + 1)
        self._scan = (s, *self.along(s))

    @classmethod
    def of(cls, surface, domain) -> "_Form | None":
        """The form of a non-periodic B-spline surface with a one-span direction of degree
        ≤ 2 (v tried first), None for any other surface."""
        if type(surface).__name__ != "BSplineSurface":
            return None
        if surface.isUPeriodic() or surface.isVPeriodic():
            return None
        u0, u1, v0, v1 = domain
        for t_is_u in (False, True):
            t_knots = surface.getUKnots() if t_is_u else surface.getVKnots()
            t_degree = surface.UDegree if t_is_u else surface.VDegree
            if len(t_knots) != 2 or t_degree > 2:
                continue
            poles = np.array([[tuple(p) for p in row] for row in surface.getPoles()])
            weights = np.array(surface.getWeights(), dtype=float)
            s_knots = surface.getVKnots() if t_is_u else surface.getUKnots()
            s_mults = surface.getVMultiplicities() if t_is_u else surface.getUMultiplicities()
            s_degree = surface.VDegree if t_is_u else surface.UDegree
            full = np.repeat(np.array(s_knots, dtype=float), s_mults)
            if t_is_u:
                poles, weights = poles.transpose(1, 0, 2), weights.T
                (s0, s1), (t0, t1) = (v0, v1), (u0, u1)
            else:
                (s0, s1), (t0, t1) = (u0, u1), (v0, v1)
            if poles.shape[1] != t_degree + 1 or len(full) != len(poles) + s_degree + 1:
                return None
            ta, tb = float(t_knots[0]), float(t_knots[1])
            sa, sb = float(s_knots[0]), float(s_knots[-1])
            ms, mt = DOMAIN_MARGIN * (s1 - s0), DOMAIN_MARGIN * (t1 - t0)

            def lam(t: float) -> float:
                return min(max((t - ta) / (tb - ta), 0.0), 1.0)

            # Widened, but never beyond the surface: a curve leaving it ends on its boundary.
            return cls(full, s_degree, poles * weights[:, :, None], weights, (ta, tb),
                       ((max(s0 - ms, sa), min(s1 + ms, sb)),
                        (max(s0 - 2 * ms, sa), min(s1 + 2 * ms, sb))),
                       ((lam(t0 - mt), lam(t1 + mt)), (lam(t0 - 2 * mt), lam(t1 + 2 * mt))))
        return None

    def along(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(A_j(s) (len, q + 1, 3), W_j(s) (len, q + 1))."""
        value = self._along(s)
        split = 3 * (self.q + 1)
        return value[:, :split].reshape(len(value), self.q + 1, 3), value[:, split:]

    def g(self, s: np.ndarray, n: np.ndarray, h: float) -> np.ndarray:
        a, w = self.along(s)
        return _plane_values(a, w, n, h)

    def point(self, s: np.ndarray, lam: np.ndarray) -> np.ndarray:
        a, w = self.along(s)
        return _rational_point(self.q, lam, a, w)

    def inside(self, s: np.ndarray, lam: np.ndarray, evaluated: bool = False) -> np.ndarray:
        """Whether (s, λ) lie in the widened face box (or the evaluated one)."""
        s0, s1 = self.s_window[evaluated]
        l0, l1 = self.t_window[evaluated]
        return (s >= s0) & (s <= s1) & (lam >= min(l0, l1)) & (lam <= max(l0, l1))

    def stretches(self, n: np.ndarray, h: float):
        """(branch, first τ, last τ, closed) of each stretch of the curve inside the widened
        face box; a None among them: the configuration is not generic."""
        s, a_scan, w_scan = self._scan
        g = _plane_values(a_scan, w_scan, n, h)
        if self.q == 1:
            yield from self._ruled(s, g, n, h)
        else:
            yield from self._lofted(s, g, n, h)

    def _ruled(self, s: np.ndarray, g: np.ndarray, n: np.ndarray, h: float):
        across = g[:, 0] - g[:, 1]
        scale = float(np.max(np.abs(g))) or 1.0
        if np.all(np.abs(across) < RULING_SHARE * scale):
            yield from self._level_rulings(s, g[:, 0], n, h)
            return
        crossing = np.flatnonzero((g[1:, 0] > 0) != (g[:-1, 0] > 0))
        if np.any(np.minimum(np.abs(across[crossing]), np.abs(across[crossing + 1]))
                  < RULING_SHARE * scale):
            yield None          # a ruling in the plane, the others crossing it
            return
        lam = g[:, 0] / across
        branch = _Branch(self, n, h, s[0], s[-1], (False, False))
        tau, flags = branch.filled(s, lam, self.inside(s, lam))
        for first, last in branch.stretches(tau, flags, False):
            yield branch, first, last, False

    def _level_rulings(self, s: np.ndarray, g0: np.ndarray, n: np.ndarray, h: float):
        """Every ruling parallel to the plane (a loft between sections in planes of this
        normal, across its straight side; an extrusion along the plane): the plane holds
        the whole rulings where g0(s) = 0 and meets no other, so each is one straight
        `_Ruling` across the widened face box. A root the scan cannot separate (g0 touching
        zero, or bending back between samples) or a ruling off the plane is not generic."""
        if _unseparated(g0):
            yield None
            return
        crossing = np.flatnonzero((g0[1:] > 0) != (g0[:-1] > 0))
        if not len(crossing):
            return

        def plane_value(x: np.ndarray) -> np.ndarray:
            return self.g(x.reshape(-1), n, h)[:, 0].reshape(x.shape)

        roots = bracketed_zeros(plane_value, s[crossing], s[crossing + 1])
        (s0, s1), _ = self.s_window
        (l0, l1), _ = self.t_window
        for root in roots[(roots >= s0) & (roots <= s1)]:
            ends = self.point(np.array([root, root]), np.array([l0, l1]))
            if not (np.all(np.isfinite(ends))
                    and np.max(np.abs(ends @ n - h)) <= PLANE_SLACK):
                yield None
                return
            yield _Ruling(ends)

    def _lofted(self, s: np.ndarray, g: np.ndarray, n: np.ndarray, h: float):
        e = _discriminant(g)
        if _unseparated(e):
            yield None
            return
        positive = e > 0
        if not positive.any():
            return
        change = np.flatnonzero(positive[1:] != positive[:-1])
        # Turning points, each on the side where the roots are complex: the two roots then
        # meet at one point there (1e-12 of the range beyond the true tip).
        turns = bracketed_zeros(lambda x: _discriminant(self.g(x.reshape(-1), n, h)).reshape(x.shape),
                                s[change], s[change + 1])
        ends = [s[0], *turns, s[-1]]
        holds = [bool(positive[0])] + [not positive[i] for i in change]
        for k, holding in enumerate(holds):
            if holding:       # E > 0 from ends[k] to ends[k + 1]: two real roots
                branch = _Branch(self, n, h, ends[k], ends[k + 1], (k > 0, k + 1 < len(ends) - 1))
                yield from self._loop(branch, s, g)

    def _loop(self, branch: "_Branch", s: np.ndarray, g: np.ndarray):
        """The stretches of both roots between two ends (turning points or the window's),
        from the scan's samples there. τ of the − root runs 0 → π from a to b, of the +
        root π → 2π back; the two join where an end is a turning point, and only there."""
        a, b = branch.a, branch.b
        pick = np.flatnonzero((s > a) & (s < b))
        ss = np.concatenate(([a], s[pick], [b]))
        at_ends = self.g(np.array([a, b]), branch.n, branch.h)
        gg = np.concatenate((at_ends[:1], g[pick], at_ends[1:]))
        m, w = 0.5 * (a + b), 0.5 * (b - a)
        angle = np.arccos(np.clip((m - ss) / w, -1.0, 1.0))
        minus, plus = _root(gg, -1.0), _root(gg, 1.0)
        low_turns, high_turns = branch.turning
        plus_tau = 2 * math.pi - angle[::-1]
        # τ = π and 2π belong to the − root (`_Branch.at`): where an end is no turning point
        # the + root's own end sample sits a hair inside (the same s to the last bit).
        if not high_turns:
            plus_tau[0] = math.pi + JUNCTION
        if not low_turns:
            plus_tau[-1] = 2 * math.pi - JUNCTION
        minus_tau, minus_flags = branch.filled(angle, minus, self.inside(ss, minus))
        plus_tau, plus_flags = branch.filled(plus_tau, plus[::-1], self.inside(ss, plus)[::-1])
        if low_turns and high_turns:
            tau = np.concatenate((minus_tau, plus_tau[1:-1]))
            flags = np.concatenate((minus_flags, plus_flags[1:-1]))
            if flags.all():
                yield branch, 0.0, 2 * math.pi, True
                return
            for first, last in branch.stretches(tau, flags, True):
                yield branch, first, last + (2 * math.pi if last <= first else 0.0), False
            return
        if high_turns:
            sequences = [(np.concatenate((minus_tau, plus_tau[1:])),
                          np.concatenate((minus_flags, plus_flags[1:])))]
        elif low_turns:
            sequences = [(np.concatenate((plus_tau, minus_tau[1:] + 2 * math.pi)),
                          np.concatenate((plus_flags, minus_flags[1:])))]
        else:
            sequences = [(minus_tau, minus_flags), (plus_tau, plus_flags)]
        for tau, flags in sequences:
            for first, last in branch.stretches(tau, flags, False):
                yield branch, first, last, False


def _unseparated(values: np.ndarray) -> bool:
    """Whether the scan may not see each zero of `values` apart: a local extremum within
    `TANGENT_SHARE` of zero (of the largest value: a near tangent), or one on the far side
    of zero within `HIDDEN_BEND` second differences of it (two zeros between samples)."""
    scale = float(np.max(np.abs(values))) or 1.0
    inner = values[1:-1]
    peak = (inner >= values[:-2]) & (inner >= values[2:])
    dip = (inner <= values[:-2]) & (inner <= values[2:])
    hidden = (((peak & (inner < 0)) | (dip & (inner > 0)))
              & (np.abs(inner) < HIDDEN_BEND * np.abs(values[:-2] - 2 * inner + values[2:])))
    return bool(np.any(((peak | dip) & (np.abs(inner) < TANGENT_SHARE * scale)) | hidden))


class _Ruling:
    """A whole ruling in the plane, between its two points at the widened box's λ ends."""

    def __init__(self, ends: np.ndarray) -> None:
        self.ends = ends

    def curve(self, Part):
        """The ruling as a degree-1 B-spline (its ends set onto the crossings as any)."""
        line = Part.BSplineCurve()
        line.buildFromPolesMultsKnots(self.ends.tolist(), [2, 2], [0.0, 1.0], False, 1)
        return line


def _root(g: np.ndarray, sign) -> np.ndarray:
    """The root λ = g0 / ((g0 − g1) + sign·√E) of Σ B_j(λ) g_j = 0 (degree 2), written as
    ((g0 − g1) − sign·√E) / (g0 − 2 g1 + g2) where that form does not cancel: where the two
    terms meet with opposite signs (the stable quadratic formula), and past a turning point
    (E < 0: its samples a hair beyond it), where it is the complex roots' real part, the
    parabola's vertex, continuous through the tip; near the λ = 0 boundary g0 ≈ g1 ≈ 0 made
    the first form 0/0 there (CrankArm's arm)."""
    across = g[:, 0] - g[:, 1]
    e = _discriminant(g)
    root = np.sqrt(np.maximum(e, 0.0))
    curved = g[:, 0] - 2 * g[:, 1] + g[:, 2]
    near = g[:, 0] / (across + sign * root)
    far = (across - sign * root) / curved
    return np.where(((sign * across <= 0) | (e <= 0)) & (curved != 0), far, near)


def _discriminant(g: np.ndarray) -> np.ndarray:
    return g[:, 1] ** 2 - g[:, 0] * g[:, 2]


def _rational_point(q: int, lam: np.ndarray, a: np.ndarray, w: np.ndarray) -> np.ndarray:
    if q == 1:
        bern = np.stack([1 - lam, lam], axis=1)
    else:
        bern = np.stack([(1 - lam) ** 2, 2 * lam * (1 - lam), lam ** 2], axis=1)
    numerator = bern[:, 0, None] * a[:, 0]
    denominator = bern[:, 0] * w[:, 0]
    for j in range(1, q + 1):
        numerator = numerator + bern[:, j, None] * a[:, j]
        denominator = denominator + bern[:, j] * w[:, j]
    return numerator / denominator[:, None]


def _plane_values(a: np.ndarray, w: np.ndarray, n: np.ndarray, h: float) -> np.ndarray:
    """g_j = n·A_j − h W_j, term by term (see bspline_numeric: no `@`)."""
    return a[..., 0] * n[0] + a[..., 1] * n[1] + a[..., 2] * n[2] - h * w


class _Branch:
    """The curve over s ∈ [a, b] in one parameter τ: degree 1, s = τ and λ(s); degree 2,
    s = m − w cos τ and the − root for τ ≤ π, the + one beyond; `turning`: whether a and b
    are turning points (where the two roots meet)."""

    def __init__(self, form: _Form, n: np.ndarray, h: float, a: float, b: float,
                 turning: tuple[bool, bool]) -> None:
        self.form, self.n, self.h = form, n, h
        self.a, self.b, self.turning = float(a), float(b), turning

    def at(self, tau: np.ndarray):
        """(s, λ, A_j(s), W_j(s)) at τ."""
        form = self.form
        tau = np.asarray(tau, dtype=float)
        if form.q == 1:
            s = tau
        else:
            tau = np.mod(tau, 2 * math.pi)
            m, w = 0.5 * (self.a + self.b), 0.5 * (self.b - self.a)
            s = np.minimum(np.maximum(m - w * np.cos(tau), self.a), self.b)
        a, weights = form.along(s)
        g = _plane_values(a, weights, self.n, self.h)
        if form.q == 1:
            lam = g[:, 0] / (g[:, 0] - g[:, 1])
        else:
            lam = _root(g, np.where(tau <= math.pi, -1.0, 1.0))
        return s, lam, a, weights

    def s_lam(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        s, lam, _, _ = self.at(tau)
        return s, lam

    def points(self, tau: np.ndarray) -> np.ndarray:
        _, lam, a, weights = self.at(tau)
        return _rational_point(self.form.q, lam, a, weights)

    def filled(self, tau: np.ndarray, lam: np.ndarray,
               flags: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(τ, inside) with `END_GRID` sub-samples wherever λ passes over the whole box
        between two samples outside it (a thread's flank crosses a thin face in less than a
        sample of the scan); their runs are then seen."""
        (l0, l1), _ = self.form.t_window
        low, high = min(l0, l1), max(l0, l1)
        steps = np.linspace(0.0, 1.0, END_GRID + 1)[1:-1]
        for _ in range(FILL_ROUNDS):
            # Both within reach: beyond it λ runs off to a pole between them (a root at
            # infinity) and comes back from the other side, crossing nothing.
            reach = (np.abs(lam[:-1] - 0.5) < FILL_REACH) & (np.abs(lam[1:] - 0.5) < FILL_REACH)
            over = (~flags[:-1] & ~flags[1:] & reach
                    & (((lam[:-1] < low) & (lam[1:] > high))
                       | ((lam[:-1] > high) & (lam[1:] < low))))
            gaps = np.flatnonzero(over)
            if not len(gaps):
                break
            sub = (tau[gaps, None] + (tau[gaps + 1] - tau[gaps])[:, None] * steps).ravel()
            s_sub, lam_sub = self.s_lam(sub)
            where = np.repeat(gaps + 1, len(steps))
            tau = np.insert(tau, where, sub)
            lam = np.insert(lam, where, lam_sub)
            flags = np.insert(flags, where, self.form.inside(s_sub, lam_sub))
        return tau, flags

    def knot_tau(self, first: float, last: float) -> np.ndarray:
        """τ in (first, last) where s crosses one of the surface's inner knots."""
        form = self.form
        knots = np.unique(form.knots[form.degree + 1:-form.degree - 1])
        if form.q == 1:
            return knots[(knots > first) & (knots < last)]
        m, w = 0.5 * (self.a + self.b), 0.5 * (self.b - self.a)
        angle = np.arccos(np.clip((m - knots[(knots > self.a) & (knots < self.b)]) / w, -1, 1))
        every = np.concatenate([angle + turn for turn in (-2 * math.pi, 0.0, 2 * math.pi, 4 * math.pi)]
                               + [2 * math.pi - angle + turn
                                  for turn in (-2 * math.pi, 0.0, 2 * math.pi)])
        return every[(every > first) & (every < last)]

    def stretches(self, tau: np.ndarray, flags: np.ndarray,
                  closed: bool) -> list[tuple[float, float]]:
        """(first τ, last τ) of each run of samples inside the widened box, each end where
        the run leaves the box (to an `END_GRID`-th of a sample); where λ leaves even the
        evaluated box within that, where it reaches the middle of the margin, or the
        surface's boundary exactly when the box reaches it (the face's edge there crosses
        the plane on it); where λ jumps instead (a root running off at a degenerate row of
        poles: the fan blades' trailing edges), at the last point inside. All ends at once:
        a thread's flank crosses a plane two dozen times."""
        runs = _runs(flags, closed)
        if not runs:
            return []
        pairs = np.array([(inside, outside) for before, first, last, after in runs
                          for inside, outside in ((first, before), (last, after))])
        start, stop = tau[pairs[:, 0]], tau[pairs[:, 1]].copy()
        if self.form.q == 2:           # a closed loop's neighbour across τ = 0 ≡ 2π
            stop += np.where(stop - start > math.pi, -2 * math.pi,
                             np.where(start - stop > math.pi, 2 * math.pi, 0.0))
        sub = start[:, None] + (stop - start)[:, None] * np.linspace(0.0, 1.0, END_GRID + 1)[1:]
        s_sub, lam = (v.reshape(sub.shape) for v in self.s_lam(sub.reshape(-1)))
        out = ~self.form.inside(s_sub, lam)
        k = np.where(out.any(axis=1), np.argmax(out, axis=1), END_GRID - 1)
        rows = np.arange(len(pairs))
        at, lam_k = sub[rows, k], lam[rows, k]
        before = np.where(k > 0, sub[rows, np.maximum(k - 1, 0)], start)
        near = self.form.inside(s_sub[rows, k], lam_k, evaluated=True)
        alone = pairs[:, 0] == pairs[:, 1]          # an open sequence's end sample, inside
        ends = np.where(alone, start, np.where(near, at, before))
        (l0, l1), (e0, e1) = self.form.t_window
        inner_low, inner_high = min(l0, l1), max(l0, l1)
        outer_low, outer_high = min(e0, e1), max(e0, e1)
        above = lam_k > outer_high
        leaves = ~near & ~alone & np.isfinite(lam_k) & ((lam_k < outer_low) | above)
        if leaves.any():
            high = outer_high if outer_high >= 1.0 else 0.5 * (inner_high + outer_high)
            low = outer_low if outer_low <= 0.0 else 0.5 * (inner_low + outer_low)
            target = np.where(above, high, low)[leaves]
            sign = np.where(above[leaves], 1.0, -1.0)

            def beyond(x: np.ndarray) -> np.ndarray:
                lam_x = self.s_lam(x.reshape(-1))[1].reshape(x.shape)
                return sign[:, None] * (lam_x - target[:, None])

            found = bracketed_zeros(beyond, before[leaves], at[leaves])
            reached = np.abs(self.s_lam(found)[1] - target) <= BOUNDARY_SLACK
            ends[leaves] = np.where(reached, found, before[leaves])
        return [(float(first), float(last)) for first, last in ends.reshape(-1, 2)]


def _runs(inside: np.ndarray, closed: bool) -> list[tuple[int, int, int, int]]:
    """(outside before, first inside, last inside, outside after) sample indices of each run
    of `inside` (an open sequence's end sample stands for its own outside neighbour); a
    closed sequence's run may wrap past its end."""
    count = len(inside)
    if not inside.any():
        return []
    start = int(np.argmin(inside)) if closed else 0
    rolled = np.roll(inside, -start)
    edges = np.flatnonzero(np.diff(np.concatenate(([0], rolled.astype(int), [0]))))
    found = []
    for first, last in zip(edges[::2], edges[1::2]):
        lo, hi = start + first, start + last - 1
        before, after = lo - 1, hi + 1
        if not closed:
            before, after = max(before, 0), min(after, count - 1)
        found.append((before % count, lo % count, hi % count, after % count))
    return found


def _fit(branch: _Branch, first: float, last: float, closed: bool, Part):
    """A cubic B-spline through exact points at τ ∈ [first, last], refined to tolerance:
    samples at every inner knot of the surface along s (the curve is only C² there, and an
    interpolant with a knot at each gets back the fourth-order convergence) and uniform
    between them, then halved where the fit strays until it nowhere does. The first count
    comes from the stretch alone, not from the curves fitted before it: a section must be
    the same bits whichever process cut which plane. None: OCC decides."""
    length = last - first
    count = (FIRST_SAMPLES if branch.form.q == 1
             else max(MIN_SAMPLES, int(FIRST_SAMPLES * length / (2 * math.pi))))
    tau = np.union1d(np.linspace(first, last, count + 1), branch.knot_tau(first, last))
    tau = tau[np.concatenate(([True], np.diff(tau) > SAME_SAMPLE * length))]
    if len(tau) < 2:
        # A stretch of one point (τ first = last): the plane touches the surface there, or
        # the scan's bracket closed on a root. No curve to fit; OCC decides.
        return None
    tau[-1] = last
    points = branch.points(tau)
    middle = 0.5 * (tau[1:] + tau[:-1])
    exact = branch.points(middle)
    previous = math.inf
    for _ in range(MAX_TRIES + 1):
        if not (np.all(np.isfinite(points)) and np.all(np.isfinite(exact))):
            return None
        n, h = branch.n, branch.h
        if max(float(np.max(np.abs(points[:, 0] * n[0] + points[:, 1] * n[1]
                                   + points[:, 2] * n[2] - h))),
               float(np.max(np.abs(exact[:, 0] * n[0] + exact[:, 1] * n[1]
                                   + exact[:, 2] * n[2] - h)))) > PLANE_SLACK:
            return None
        spline = Part.BSplineCurve()
        try:
            if closed:
                spline.interpolate(Points=points[:-1].tolist(), PeriodicFlag=True,
                                   Parameters=tau.tolist())
            else:
                spline.interpolate(Points=points.tolist(), Parameters=tau.tolist())
        except Exception:  # noqa: BLE001 - OCC raises bare Standard_Failure types here
            return None
        offset = curve_points(spline, middle) - exact
        # The distance from the exact curve, not from its point at the same τ: an error
        # along the curve (the parametrisation's) moves no point off it. The chord between
        # two samples gives the direction to within the fit's concern.
        chord = points[1:] - points[:-1]
        chord /= np.maximum(_norms(chord), 1e-300)[:, None]
        along = offset[:, 0] * chord[:, 0] + offset[:, 1] * chord[:, 1] + offset[:, 2] * chord[:, 2]
        across = _norms(offset - along[:, None] * chord)
        strays = across > FIT_TOLERANCE
        if not strays.any():
            return spline
        deviation = float(across.max())
        if ((deviation > FAIL_FLOOR * FIT_TOLERANCE and deviation > previous / FAIL_RATIO)
                or len(tau) + 3 * int(strays.sum()) > MAX_SAMPLES):
            return None     # more samples do not help: not a smooth curve
        previous = deviation
        tau, points, middle, exact = _refined(branch, tau, points, middle, exact, across)
    return None


def _norms(rows: np.ndarray) -> np.ndarray:
    return np.sqrt(rows[:, 0] * rows[:, 0] + rows[:, 1] * rows[:, 1] + rows[:, 2] * rows[:, 2])


def _refined(branch: _Branch, tau, points, middle, exact, across):
    """Samples and middles with each interval whose fit strays beyond `SPLIT_SHARE` of the
    tolerance, and its neighbours (an interpolant's error spreads a little), split into as
    many as its deviation asks for: the error falls as the fourth power of the spacing, so
    one try mostly meets the tolerance where halving took three."""
    wanted = np.ceil(np.maximum(across / (SPLIT_SHARE * FIT_TOLERANCE), 1.0) ** 0.25)
    pieces = np.maximum.reduce([wanted, np.concatenate(([1.0], wanted[:-1])),
                                np.concatenate((wanted[1:], [1.0]))])
    pieces = np.minimum(pieces, MAX_SPLIT).astype(int)
    split = pieces > 1
    # each interval k becomes pieces[k] intervals, starting at tau[k]
    starts = np.concatenate(([0], np.cumsum(pieces)[:-1]))
    new_tau = np.empty(int(pieces.sum()) + 1)
    new_tau[-1] = tau[-1]
    index = np.repeat(np.arange(len(pieces)), pieces)
    step = np.arange(len(index)) - starts[index]
    new_tau[:-1] = tau[index] + (tau[index + 1] - tau[index]) * step / pieces[index]
    new_points = np.empty((len(new_tau), 3))
    old = np.zeros(len(new_tau), dtype=bool)
    old[starts] = True
    old[-1] = True
    new_points[starts], new_points[-1] = points[:-1], points[-1]
    new_points[~old] = branch.points(new_tau[~old])
    new_middle = 0.5 * (new_tau[1:] + new_tau[:-1])
    new_exact = np.empty((len(new_middle), 3))
    kept = starts[~split]
    new_exact[kept] = exact[~split]
    fresh = np.ones(len(new_middle), dtype=bool)
    fresh[kept] = False
    new_exact[fresh] = branch.points(new_middle[fresh])
    return new_tau, new_points, new_middle, new_exact
