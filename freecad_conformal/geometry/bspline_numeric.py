"""B-spline evaluation and root bracketing in numpy, many points at once.

FreeCAD evaluates a curve or surface one point per call; the closed-form sections
(`spline_sections.py`) evaluate hundreds at a time. Sums are written out term by term in a
fixed order, never `@`, `einsum` or LAPACK: those dispatch to kernels whose summation order
(and fused multiply-adds) depend on the arrays' alignment, so one process's points could
differ in the last bit from another's, and a section must be the same bits whichever
process cut it (test_sections' fork-server test caught it).
"""
from __future__ import annotations

from typing import Callable

import numpy as np

from freecad_conformal.geometry.frames import points_array

#: Points per round and rounds of the sub-grids that narrow a bracket: 32⁶ ≈ 1e9-fold, so a
#: zero bracketed by a thousandth of a range is found within ~1e-12 of it.
ZERO_GRID = 33
ZERO_ROUNDS = 6


def basis(knots: np.ndarray, degree: int, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(first index, values (len(x), degree + 1)) of the B-spline basis functions that do not
    vanish at each x (Cox–de Boor, a row of the triangle at a time); `knots` with their
    multiplicities; x beyond the knots takes the end span's polynomial."""
    x = np.asarray(x, dtype=float)
    k = np.clip(np.searchsorted(knots, x, side="right") - 1, degree, len(knots) - degree - 2)
    steps = np.arange(1, degree + 1)
    left = x[:, None] - knots[k[:, None] + 1 - steps]        # left[:, j - 1] = x - U[k + 1 - j]
    right = knots[k[:, None] + steps] - x[:, None]           # right[:, j - 1] = U[k + j] - x
    values = np.ones((len(x), 1))
    for j in range(1, degree + 1):
        # N_r ← right_{r+1}·T_r + left_{j-r+1}·T_{r-1}, T_r = N_r / (right_{r+1} + left_{j-r})
        r_part = right[:, :j]
        l_part = left[:, j - 1::-1]
        temp = values / (r_part + l_part)
        grown = np.zeros((len(x), j + 1))
        grown[:, :j] = r_part * temp
        grown[:, 1:] += l_part * temp
        values = grown
    return k - degree, values


def combine(first: np.ndarray, values: np.ndarray, coefficients: np.ndarray) -> np.ndarray:
    """Σ_r values[:, r] · coefficients[first + r] (coefficients (n, ...)): `basis`'s
    functions applied to poles or any per-pole values."""
    shape = (len(first),) + (1,) * (coefficients.ndim - 1)
    total = values[:, 0].reshape(shape) * coefficients[first]
    for r in range(1, values.shape[1]):
        total = total + values[:, r].reshape(shape) * coefficients[first + r]
    return total


class PowerPieces:
    """The spline Σ N_i(s) c_i as one polynomial per knot span in the span's own coordinate
    u = 2(s − left)/(right − left) − 1, evaluated by Horner's rule: ~10 numpy steps a call
    for a degree-9 thread where the Cox–de Boor triangle and the gather take ~80. Each
    span's polynomial is fitted exactly at its Chebyshev nodes (one well-conditioned
    Vandermonde system for all spans): within 1e-10 mm of FreeCAD's own points on the
    shared parts' and the own parts' surfaces (degree 12 at most)."""

    def __init__(self, knots: np.ndarray, degree: int, coefficients: np.ndarray) -> None:
        self.degree = degree
        self.breaks = np.unique(knots[degree:len(knots) - degree])
        nodes = -np.cos(np.pi * (np.arange(degree + 1) + 0.5) / (degree + 1))
        inverse = _lagrange_power(nodes)
        widths = self.breaks[1:] - self.breaks[:-1]
        at = (self.breaks[:-1, None] + widths[:, None] * 0.5 * (nodes + 1)).reshape(-1)
        first, values = basis(knots, degree, at)
        sampled = combine(first, values, coefficients.reshape(len(coefficients), -1))
        sampled = sampled.reshape(len(self.breaks) - 1, degree + 1, -1)
        #: (spans, degree + 1, values): the power coefficients of each span
        self.coefficients = np.stack(
            [sum((inverse[i, j] * sampled[:, j] for j in range(1, degree + 1)),
                 inverse[i, 0] * sampled[:, 0]) for i in range(degree + 1)], axis=1)
        self.shape = coefficients.shape[1:]

    def __call__(self, s: np.ndarray) -> np.ndarray:
        """The spline's values at s, (len(s), *shape of one coefficient)."""
        s = np.asarray(s, dtype=float)
        breaks = self.breaks
        span = np.minimum(np.maximum(np.searchsorted(breaks, s, side="right") - 1, 0),
                          len(breaks) - 2)
        u = (2.0 * (s - breaks[span]) / (breaks[span + 1] - breaks[span]) - 1.0)[:, None]
        local = self.coefficients[span]
        value = local[:, -1]
        for power in range(self.degree - 1, -1, -1):
            value = value * u + local[:, power]
        return value.reshape((len(s),) + self.shape)


def _lagrange_power(nodes: np.ndarray) -> np.ndarray:
    """M with M[i, j] the coefficient of u^i in the Lagrange polynomial of node j: the
    inverse of the nodes' Vandermonde matrix, expanded product by product in Python."""
    count = len(nodes)
    matrix = np.zeros((count, count))
    for j in range(count):
        polynomial = [1.0]                      # coefficients, lowest power first
        scale = 1.0
        for m in range(count):
            if m == j:
                continue
            node = float(nodes[m])
            polynomial = ([-node * polynomial[0]]
                          + [polynomial[i - 1] - node * polynomial[i] for i in range(1, len(polynomial))]
                          + [polynomial[-1]])
            scale *= float(nodes[j]) - node
        matrix[:, j] = [c / scale for c in polynomial]
    return matrix


def curve_points(spline, t: np.ndarray) -> np.ndarray:
    """Points (len(t), 3) of a non-rational FreeCAD B-spline curve at parameters t."""
    if spline.isPeriodic():
        return np.array([tuple(spline.value(float(x))) for x in t])
    poles = points_array(spline.getPoles())
    knots = np.repeat(np.array(spline.getKnots()), spline.getMultiplicities())
    first, values = basis(knots, spline.Degree, t)
    return combine(first, values, poles)


def bracketed_zeros(f: Callable[[np.ndarray], np.ndarray], a: np.ndarray,
                    b: np.ndarray) -> np.ndarray:
    """Zeros of f bracketed by [a, b] (f of opposite signs at the two ends), all at once:
    f maps rows of points, one row per bracket, to their values. Each round evaluates f on
    a sub-grid of `ZERO_GRID` points across every bracket and keeps the cell where the sign
    first changes: robust where f bends or jumps, as regula falsi is not.
    Each is returned on its f ≤ 0 side (where the callers' roots are complex, or λ still
    within the surface)."""
    a, b = np.array(a, dtype=float), np.array(b, dtype=float)
    a, b = np.minimum(a, b), np.maximum(a, b)
    count = len(a)
    fraction = np.linspace(0.0, 1.0, ZERO_GRID)
    rows = np.arange(count)
    fa = np.zeros(count)
    for _ in range(ZERO_ROUNDS):
        x = a[:, None] + (b - a)[:, None] * fraction
        fx = f(x)
        positive = fx > 0
        cell = np.argmax(positive[:, 1:] != positive[:, :1], axis=1)
        a, b = x[rows, cell], x[rows, cell + 1]
        fa = fx[rows, cell]
    return np.where(fa <= 0, a, b)
