"""The DOE analysis as one call: effects on the mean and on ln s², Lenth margins, half-normal
plot data, location and dispersion models, and the optimum in coded and real units.

    data = RunData.from_replicates(read_table("results.csv", ["y"]), "y")
    result = analyze(data, location=["D", "A"], dispersion=["B", "D", "C"], goal="larger",
                     response_scale=3.556, response_unit="mm/s")
    result.to_dict()["optimum"]["predicted_real"]   # 0.712 · Vmax = 2.53 mm/s

Terms may be a list of effect words (aliases accepted), "lenth" (beyond Lenth's margin of
error), "lenth-sme" (beyond the simultaneous margin) or None (intercept only).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

from freecad_conformal.errors import ProcessError
from freecad_conformal.process.doe.design import Design
from freecad_conformal.process.doe.effects import Contrast, RunData, contrasts, effects
from freecad_conformal.process.doe.models import (
    GOALS, Model, Optimum, find_optimum, fit, resolve_terms, significant_terms)
from freecad_conformal.process.doe.stats import Lenth, half_normal_quantiles, lenth

SELECTIONS = ("lenth", "lenth-sme")
Terms = Sequence[str] | str | None


@dataclass
class HalfNormal:
    """Points of a half-normal plot: labels by increasing |effect| and their quantiles."""

    labels: list[str]
    magnitudes: list[float]
    quantiles: list[float]

    @classmethod
    def of(cls, effect_values: dict[str, float]) -> "HalfNormal":
        order = sorted(effect_values, key=lambda label: abs(effect_values[label]))
        return cls(order, [abs(effect_values[k]) for k in order],
                   half_normal_quantiles(len(order)).tolist())

    def to_dict(self) -> dict:
        return {"labels": self.labels, "abs_effects": self.magnitudes,
                "quantiles": self.quantiles}


@dataclass
class Analysis:
    """Everything `analyze` found; `to_dict` is the --json output."""

    names: list[str]
    contrasts: list[Contrast]
    defining_relation: list[tuple[str, int]]
    effects_mean: dict[str, float]
    effects_ln_s2: dict[str, float] | None
    lenth_mean: Lenth
    lenth_ln_s2: Lenth | None
    location: Model
    dispersion: Model | None
    optimum: Optimum
    settings: dict[str, float | str]
    response_scale: float | None = None
    response_unit: str = ""
    source: str = ""
    notes: list[str] = field(default_factory=list)

    @property
    def predicted_real(self) -> float | None:
        """The optimum's predicted response in real units (e.g. V = coefficient × Vmax)."""
        return self.optimum.mean * self.response_scale if self.response_scale else None

    def half_normal(self, which: str = "mean") -> HalfNormal:
        values = self.effects_mean if which == "mean" else self.effects_ln_s2
        if values is None:
            raise ProcessError("no ln s² effects: the data carry no replicate variance")
        return HalfNormal.of(values)

    def to_dict(self) -> dict:
        optimum = {"goal": self.optimum.goal, "coded": self.optimum.coded,
                   "settings": self.settings, "predicted_mean": self.optimum.mean,
                   "predicted_ln_s2": self.optimum.ln_s2, "predicted_std": self.optimum.std,
                   "free_factors": self.optimum.free}
        if self.optimum.target is not None:
            optimum["target"] = self.optimum.target
        if self.response_scale:
            optimum.update(predicted_real=self.predicted_real, response_scale=self.response_scale,
                           real_unit=self.response_unit)
        return {
            "source": self.source,
            "factors": self.names,
            "defining_relation": [("-" if s < 0 else "") + w for w, s in self.defining_relation],
            "aliases": {c.label: c.alias_text() for c in self.contrasts},
            "effects": {"mean": self.effects_mean, "ln_s2": self.effects_ln_s2},
            "lenth": {"mean": self.lenth_mean.to_dict(),
                      "ln_s2": self.lenth_ln_s2.to_dict() if self.lenth_ln_s2 else None},
            "half_normal": {"mean": self.half_normal("mean").to_dict(),
                            "ln_s2": (self.half_normal("ln_s2").to_dict()
                                      if self.effects_ln_s2 is not None else None)},
            "models": {"location": self.location.to_dict(),
                       "dispersion": self.dispersion.to_dict() if self.dispersion else None},
            "optimum": optimum,
            "notes": self.notes,
        }


def _choose(terms: Terms, effect_values: dict[str, float], margins: Lenth,
            contrast_list: list[Contrast]) -> list[str]:
    if terms is None:
        return []
    if isinstance(terms, str):
        if terms not in SELECTIONS:
            raise ProcessError(f"term selection must be a list of effects or one of "
                               f"{', '.join(SELECTIONS)}, got {terms!r}")
        return significant_terms(effect_values, margins, simultaneous=terms == "lenth-sme")
    return resolve_terms(terms, contrast_list)


def analyze(data: RunData, location: Terms = "lenth", dispersion: Terms = "lenth",
            goal: str = "larger", target: float | None = None, alpha: float = 0.05,
            design: Design | None = None, response_scale: float | None = None,
            response_unit: str = "") -> Analysis:
    """Analyse per-run data; see the module docstring. `design` supplies real factor levels
    for the optimum (coded levels are reported otherwise)."""
    if goal not in GOALS:
        raise ProcessError(f"goal must be one of {', '.join(GOALS)}, got {goal!r}")
    if response_scale is not None and not response_scale > 0:
        raise ProcessError(f"response scale must be > 0, got {response_scale!r}")
    contrast_list, defining = contrasts(data.points, data.names)
    effects_mean = effects(data.means, contrast_list)
    lenth_mean = lenth(list(effects_mean.values()), alpha)
    location_model = fit(data.means, effects_mean, _choose(location, effects_mean, lenth_mean,
                                                           contrast_list))
    notes = list(data.notes)
    effects_ln_s2 = lenth_ln_s2 = dispersion_model = None
    if data.ln_s2 is not None:
        effects_ln_s2 = effects(data.ln_s2, contrast_list)
        lenth_ln_s2 = lenth(list(effects_ln_s2.values()), alpha)
        dispersion_model = fit(data.ln_s2, effects_ln_s2,
                               _choose(dispersion, effects_ln_s2, lenth_ln_s2, contrast_list))
    elif dispersion not in (None, "lenth", "lenth-sme"):
        raise ProcessError("dispersion terms were asked for, but the data carry no replicate "
                           "variance (ln s²)")
    if not location_model.coefficients:
        notes.append("no location effect selected: the location model is the grand mean "
                     "(choose effects explicitly, e.g. --location D,A)")
    if data.centre_values.size:
        curvature = float(data.centre_values.mean() - data.means.mean())
        notes.append(f"centre points: mean {data.centre_values.mean():.5g}, curvature "
                     f"(centre − corner mean) {curvature:.5g}")
    numeric = [f.name for f in design.factors if f.is_numeric] if design else []
    optimum = find_optimum(data.names, location_model, dispersion_model, goal, target, numeric)
    settings: dict[str, float | str] = (
        {name: design.factor(name).real(level) for name, level in optimum.coded.items()}
        if design else dict(optimum.coded))
    return Analysis(data.names, contrast_list, defining, effects_mean, effects_ln_s2, lenth_mean,
                    lenth_ln_s2, location_model, dispersion_model, optimum, settings,
                    response_scale, response_unit, data.source, notes)

