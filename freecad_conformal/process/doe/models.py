"""Regression models from chosen effects, and the optimum setting they predict.

With coded ±1 factors a model coefficient is half the effect and the intercept is the grand
mean (METHODS section 2). The location model predicts the mean; the dispersion model ln s².
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Iterable, Mapping, Sequence

import numpy as np

from freecad_conformal.errors import ProcessError
from freecad_conformal.process.doe.effects import Contrast
from freecad_conformal.process.doe.stats import Lenth
from freecad_conformal.process.doe.words import label_key

GOALS = ("larger", "smaller", "nominal")
#: Predictions closer than this (relative to the largest term) are ties in the optimum
#: search; floating sums of the same terms in another order differ by ~1e-16.
TIE_TOLERANCE = 1e-9
#: Grid over [−1, 1] when a numeric factor is tuned to hit a nominal target (0.005 coded).
NOMINAL_GRID = np.linspace(-1.0, 1.0, 401)


@dataclass
class Model:
    """ŷ = intercept + Σ coefficient·(product of the coded factors of the term)."""

    intercept: float
    coefficients: dict[str, float] = field(default_factory=dict)

    def predict(self, coded: Mapping[str, float]) -> float:
        return self.intercept + sum(c * math.prod(coded[letter] for letter in term)
                                    for term, c in self.coefficients.items())

    def factors(self) -> set[str]:
        return set("".join(self.coefficients))

    def formula(self, response: str = "y") -> str:
        text = f"{response} = {self.intercept:.5g}"
        for term, c in self.coefficients.items():
            text += f" {'-' if c < 0 else '+'} {abs(c):.5g}·x{term}"
        return text

    def to_dict(self) -> dict:
        return {"intercept": self.intercept, "coefficients": dict(self.coefficients)}


def resolve_terms(requested: Iterable[str], contrast_list: Sequence[Contrast]) -> list[str]:
    """Map the words asked for (labels or any alias, e.g. CD for AB) to contrast labels."""
    by_word: dict[str, str] = {}
    for c in contrast_list:
        by_word[c.label] = c.label
        for word, _ in c.aliases:
            by_word[word] = c.label
    labels = []
    for word in requested:
        key = "".join(sorted(word.strip().upper()))
        if key not in by_word:
            raise ProcessError(f"effect {word!r} is not estimable here; estimable: "
                               f"{', '.join(c.label for c in contrast_list)}")
        if by_word[key] not in labels:
            labels.append(by_word[key])
    return labels


def significant_terms(effect_values: Mapping[str, float], margins: Lenth,
                      simultaneous: bool = False) -> list[str]:
    """Effects beyond Lenth's margin of error (ME; SME when `simultaneous`), largest first."""
    limit = margins.sme if simultaneous else margins.me
    chosen = [label for label, value in effect_values.items() if abs(value) > limit]
    return sorted(chosen, key=lambda label: -abs(effect_values[label]))


def fit(values: np.ndarray, effect_values: Mapping[str, float], terms: Sequence[str]) -> Model:
    """Model from chosen effects: intercept = grand mean, coefficient = effect / 2."""
    return Model(float(np.mean(values)), {t: effect_values[t] / 2.0 for t in terms})


@dataclass
class Optimum:
    """Best coded setting, what the models predict there, and factors no model uses."""

    goal: str
    coded: dict[str, float]
    mean: float
    ln_s2: float | None
    free: list[str]
    target: float | None = None

    @property
    def std(self) -> float | None:
        return math.exp(self.ln_s2 / 2.0) if self.ln_s2 is not None else None


def find_optimum(names: Sequence[str], location: Model, dispersion: Model | None, goal: str,
                 target: float | None = None, numeric: Sequence[str] = ()) -> Optimum:
    """Best setting over the corners of the coded cube.

    larger / smaller: the location model decides first; among equal predictions the lowest
    predicted ln s² wins (the two-step of METHODS: A, D maximise ŷ, then B, C minimise s²).
    nominal: the smallest expected squared loss (ŷ − target)² + ŝ², where from every corner
    the numeric factors in `numeric` are tuned over [−1, 1] (qualitative ones stay ±1).
    Factors in no model are reported as free and left at their low level.
    """
    if goal not in GOALS:
        raise ProcessError(f"goal must be one of {', '.join(GOALS)}, got {goal!r}")
    if goal == "nominal" and target is None:
        raise ProcessError("a nominal-the-better optimum needs a target value")
    if target is not None and not math.isfinite(target):
        raise ProcessError(f"the target of a nominal-the-better response must be a finite "
                           f"number, got {target}")
    scale = max([abs(location.intercept)] + [abs(c) for c in location.coefficients.values()])
    best_key: tuple | None = None
    best: dict[str, float] | None = None
    for levels in itertools.product((-1.0, 1.0), repeat=len(names)):
        coded = dict(zip(names, levels))
        if goal == "nominal":  # the loss surface is not convex: tune from every corner
            coded = _tune_nominal(coded, location, dispersion, target, numeric)
        key = _objective(coded, location, dispersion, goal, target, scale)
        if best_key is None or key < best_key:
            best_key, best = key, coded
    assert best is not None, "itertools.product yields at least one corner"
    used = location.factors() | (dispersion.factors() if dispersion else set())
    free = [n for n in names if n not in used]
    for name in free:
        best[name] = -1.0
    return Optimum(goal, best, location.predict(best),
                   dispersion.predict(best) if dispersion else None, free, target)


def _objective(coded, location, dispersion, goal, target, scale) -> tuple:
    mean = location.predict(coded)
    ln_s2 = dispersion.predict(coded) if dispersion else 0.0
    if goal == "nominal":
        return ((mean - target) ** 2 + (math.exp(ln_s2) if dispersion else 0.0),)
    primary = -mean if goal == "larger" else mean
    # rounding to the tie tolerance makes equal predictions equal, so ln s² decides them
    return round(primary / (scale * TIE_TOLERANCE)), ln_s2


def _tune_nominal(coded, location, dispersion, target, numeric) -> dict[str, float]:
    """Coordinate descent over the numeric factors, each scanned on NOMINAL_GRID at once
    (the models accept arrays); stops when a sweep changes nothing."""
    def loss(point):
        variance = np.exp(dispersion.predict(point)) if dispersion else 0.0
        return (location.predict(point) - target) ** 2 + variance

    best = dict(coded)
    for _ in range(10):
        moved = False
        for name in numeric:
            level = float(NOMINAL_GRID[int(np.argmin(loss({**best, name: NOMINAL_GRID})))])
            moved |= level != best[name]
            best[name] = level
        if not moved:
            break
    return best


def sorted_terms(terms: Iterable[str]) -> list[str]:
    return sorted(terms, key=label_key)
