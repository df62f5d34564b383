"""The few statistics the DOE analysis needs, in plain Python (no scipy for Addon users):
Student's t quantile, half-normal plotting positions, and Lenth's pseudo standard error."""
from __future__ import annotations

import math
from dataclasses import dataclass
from statistics import NormalDist
from typing import Sequence

import numpy as np

from freecad_conformal.errors import ProcessError

#: Continued-fraction convergence: relative change below this ends the iteration; 1e-14 is a
#: few ulps above double precision, far finer than any quantile a DOE report prints.
_CF_EPS = 1e-14
_CF_MAX_ITER = 500
#: Smallest denominator allowed in the modified Lentz recurrence (avoids division by zero).
_CF_TINY = 1e-300


def _beta_continued_fraction(a: float, b: float, x: float) -> float:
    """Continued fraction of the incomplete beta function, evaluated by Lentz's method."""
    c, d = 1.0, 1.0 - (a + b) * x / (a + 1.0)
    d = 1.0 / (d if abs(d) > _CF_TINY else _CF_TINY)
    result = d
    for m in range(1, _CF_MAX_ITER + 1):
        for numerator in (m * (b - m) * x / ((a + 2 * m - 1) * (a + 2 * m)),
                          -(a + m) * (a + b + m) * x / ((a + 2 * m) * (a + 2 * m + 1))):
            d = 1.0 + numerator * d
            d = 1.0 / (d if abs(d) > _CF_TINY else _CF_TINY)
            c = 1.0 + numerator / c
            c = c if abs(c) > _CF_TINY else _CF_TINY
            result *= c * d
        if abs(c * d - 1.0) < _CF_EPS:
            return result
    raise ProcessError(f"incomplete beta I_x({a:g}, {b:g}) at x = {x:g} did not converge")


def regularized_beta(a: float, b: float, x: float) -> float:
    """I_x(a, b), the regularized incomplete beta function, for a, b > 0 and 0 <= x <= 1."""
    if x <= 0.0:
        return 0.0
    if x >= 1.0:
        return 1.0
    log_front = (math.lgamma(a + b) - math.lgamma(a) - math.lgamma(b)
                 + a * math.log(x) + b * math.log1p(-x))
    # the continued fraction converges fast for x < (a+1)/(a+b+2); use symmetry otherwise
    if x < (a + 1.0) / (a + b + 2.0):
        return math.exp(log_front) * _beta_continued_fraction(a, b, x) / a
    return 1.0 - math.exp(log_front) * _beta_continued_fraction(b, a, 1.0 - x) / b


def t_cdf(t: float, dof: float) -> float:
    """P(T <= t) for Student's t with `dof` (possibly fractional) degrees of freedom."""
    tail = 0.5 * regularized_beta(dof / 2.0, 0.5, dof / (dof + t * t))
    return 1.0 - tail if t >= 0 else tail


def t_quantile(p: float, dof: float) -> float:
    """The t value with P(T <= t) = p, by bisection on `t_cdf` (monotone)."""
    if not (0.0 < p < 1.0) or not dof > 0:
        raise ProcessError(f"t quantile needs 0 < p < 1 and dof > 0, got p={p!r}, dof={dof!r}")
    if p < 0.5:
        return -t_quantile(1.0 - p, dof)
    low, high = 0.0, 1.0
    while t_cdf(high, dof) < p:
        high *= 2.0
    for _ in range(200):
        mid = 0.5 * (low + high)
        if t_cdf(mid, dof) < p:
            low = mid
        else:
            high = mid
        if high - low <= 1e-12 * max(1.0, high):
            break
    return 0.5 * (low + high)


def half_normal_quantiles(count: int) -> np.ndarray:
    """Plotting positions Φ⁻¹(0.5 + 0.5·(i − 0.5)/m), i = 1..m, for sorted |effects|."""
    normal = NormalDist()
    return np.array([normal.inv_cdf(0.5 + 0.5 * (i - 0.5) / count) for i in range(1, count + 1)])


@dataclass(frozen=True)
class Lenth:
    """Lenth's (1989) pseudo standard error and margins for m unreplicated contrasts:
    s0 = 1.5·median|c|, PSE = 1.5·median{|c| : |c| < 2.5·s0}, d = m/3 degrees of freedom,
    ME = t(1 − α/2, d)·PSE (individual), SME = t(γ, d)·PSE with γ = (1 + (1 − α)^(1/m))/2
    (simultaneous)."""

    pse: float
    me: float
    sme: float
    dof: float
    alpha: float

    def to_dict(self) -> dict:
        return {"pse": self.pse, "me": self.me, "sme": self.sme, "dof": self.dof,
                "alpha": self.alpha}


def lenth(contrasts: Sequence[float], alpha: float = 0.05) -> Lenth:
    values = np.abs(np.asarray(contrasts, dtype=float))
    count = values.size
    if count < 2:
        raise ProcessError(f"Lenth's method needs at least 2 effects, got {count}")
    if not 0 < alpha < 1:
        raise ProcessError(f"significance level alpha must be in (0, 1), got {alpha!r}")
    s0 = 1.5 * float(np.median(values))
    trimmed = values[values < 2.5 * s0]
    pse = 1.5 * float(np.median(trimmed)) if trimmed.size else s0
    dof = count / 3.0
    gamma = 0.5 * (1.0 + (1.0 - alpha) ** (1.0 / count))
    return Lenth(pse, t_quantile(1.0 - alpha / 2.0, dof) * pse, t_quantile(gamma, dof) * pse,
                 dof, alpha)
