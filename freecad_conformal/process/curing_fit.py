"""Calibrating the working curve of a tool and resin from measured lines and rods (METHODS 1–2).

The curing model (process/curing.py) gives, for a line drawn at speed v with power P,

    Lw = B·sqrt(Cd/(2·Dp)),  Cd = Dp·ln(E/Ec),  E = K·P/(B·v)   →   Lw² = (B²/2)·ln(vc/v)

with vc = K·P/(B·Ec) the speed at which the exposure falls to Ec (nothing cures faster).
Dp cancels out of the width: widths calibrate B and Ec, never Dp (that needs a depth
measurement; it stays the datasheet value in the tool's settings).

How the constants are fitted from measurements (`CurePoint`: power, speed, width; width 0
records "nothing cured at this speed"): with x = ln(P/v) and y = Lw² the model is the straight
line y = a·x + c with a = Beff²/2 and c = a·ln(vc/P). Least squares on (x, y) over all points
gives a and c, hence the effective spot Beff = sqrt(2a) and vc per watt = exp(c/a).

- One width measured (e.g. a DOE optimum: 2.53 mm/s at 495 mW gives the tool's finest line)
  fixes c with a from the nominal spot B (the published model as it stands).
- Two or more (a width and a speed where nothing cures; several speeds of a DOE) fit both:
  Beff then differs from the fibre core where the light spreads in the resin (the large
  tool's 2.3 mm wall at 0.4 mm/s and its ~0.75 mm/s cut-off give Beff ≈ 4.1 mm).
- Point curing (rods: the tool moves along its own axis) has the same form (the dose at a
  point as the tip passes is ∝ P/v); with one measured rod and no cut-off, the cut-off of
  the same tool's line fit is taken (the same dose per time at the tip cures nothing).

`fit_speed_factors` fits the DOE table itself: the fastest speed for a fixed width is ∝ P
(the model), and the other factors (gap, base, strategy) change the effective Ec, so
ln v = ln P + β0 + Σ βj·xj (coded ±1 levels), least squares.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from freecad_conformal.errors import ProcessError
from freecad_conformal.process.curing import exposure_speed_product

MOTIONS = ("line", "point")
_SECONDS_PER_MINUTE = 60.0


@dataclass(frozen=True)
class CurePoint:
    """One measurement: at `power` W and `speed` mm/s the line (or rod) was `width` mm wide
    (0: nothing cured at this speed)."""

    power: float
    speed: float
    width: float
    source: str = ""

    def check(self, where: str) -> None:
        for name, value in (("power", self.power), ("speed", self.speed)):
            if not (math.isfinite(value) and value > 0):
                raise ProcessError(f"{where}: {name} must be > 0, got {value!r}")
        if not (math.isfinite(self.width) and self.width >= 0):
            raise ProcessError(f"{where}: width must be >= 0 mm, got {self.width!r}")

    def to_dict(self) -> dict:
        data: dict[str, float | str] = {"power_w": self.power, "speed_mm_s": self.speed,
                                        "width": self.width}
        if self.source:
            data["source"] = self.source
        return data


@dataclass(frozen=True)
class WorkingCurveFit:
    """Lw(P, v) = spot·sqrt(ln(cutoff_per_watt·P / v) / 2) for one tool and resin."""

    motion: str
    spot: float                 # effective spot Beff (mm)
    cutoff_per_watt: float      # vc / P (mm/s per W)
    nominal_spot: float         # the tool's spot B (mm)
    rms_error: float            # RMS width error over the points (mm)
    points: tuple[CurePoint, ...] = ()

    def cutoff_speed(self, power: float) -> float:
        """Speed (mm/s) at which nothing cures any more at `power` W."""
        return self.cutoff_per_watt * power

    def width(self, power: float, speed: float) -> float:
        """Line width / rod diameter (mm) at `power` W and `speed` mm/s (0 when nothing cures)."""
        ratio = self.cutoff_speed(power) / speed
        return self.spot * math.sqrt(math.log(ratio) / 2.0) if ratio > 1.0 else 0.0

    def speed_for_width(self, power: float, width: float) -> float:
        """Speed (mm/s) that cures `width` mm at `power` W."""
        if not (width > 0 and math.isfinite(width)):
            raise ProcessError(f"{self.motion} curing: width must be > 0 mm, got {width!r}")
        if not power > 0:
            raise ProcessError(f"{self.motion} curing: power must be > 0 W, got {power!r}")
        return self.cutoff_speed(power) * math.exp(-2.0 * (width / self.spot) ** 2)

    def feed_for_width(self, power: float, width: float) -> float:
        """The same in mm/min (the toolpath's unit)."""
        return self.speed_for_width(power, width) * _SECONDS_PER_MINUTE

    def critical_exposure(self, profile: str = "gaussian") -> float:
        """Ec (mJ/cm²) implied by the cut-off with the nominal spot's exposure formula."""
        return exposure_speed_product(1.0, self.nominal_spot, profile) / self.cutoff_per_watt

    def describe(self) -> str:
        return (f"{self.motion} curing fit: Beff {self.spot:.3g} mm (core {self.nominal_spot:g}), "
                f"cut-off {self.cutoff_per_watt:.4g} mm/s per W, from {len(self.points)} "
                f"point(s), RMS width error {self.rms_error:.3g} mm")


def fit_working_curve(points: list[CurePoint], nominal_spot: float, motion: str = "line",
                      cutoff_per_watt: float | None = None) -> WorkingCurveFit:
    """Fit Beff and the cut-off to `points` (see the module docstring); `cutoff_per_watt`
    fixes the cut-off when only one width is known and no zero-width point is given."""
    if motion not in MOTIONS:
        raise ProcessError(f"curing fit: motion must be one of {', '.join(MOTIONS)}, got {motion!r}")
    if not nominal_spot > 0:
        raise ProcessError(f"curing fit: the nominal spot must be > 0 mm, got {nominal_spot!r}")
    if not points:
        raise ProcessError(f"{motion} curing fit: no calibration point")
    for k, point in enumerate(points):
        point.check(f"{motion} curing point {k + 1}")
    x = np.array([math.log(p.power / p.speed) for p in points])
    y = np.array([p.width ** 2 for p in points])
    if not np.any(y > 0):
        raise ProcessError(f"{motion} curing fit: every point says nothing cured; at least one "
                           "measured width is needed")
    if len(points) >= 2 and np.ptp(x) > 1e-9:
        a, c = np.polyfit(x, y, 1)
        if not a > 0:
            raise ProcessError(f"{motion} curing fit: widths do not shrink with speed in the "
                               f"points given (slope {a:.3g} mm² per ln unit); check the data")
    elif cutoff_per_watt is not None and len(points) == 1:
        (xs,), (ys,) = x, y
        log_ratio = math.log(cutoff_per_watt) + xs
        if not log_ratio > 0:
            raise ProcessError(f"{motion} curing fit: the point at {points[0].speed:g} mm/s is "
                               f"faster than the cut-off {cutoff_per_watt * points[0].power:.4g} mm/s")
        a, c = ys / log_ratio, ys - (ys / log_ratio) * xs
    else:
        a = nominal_spot ** 2 / 2.0
        c = float(np.mean(y - a * x))
    spot, cutoff = math.sqrt(2.0 * a), math.exp(c / a)
    predicted = np.sqrt(np.clip(a * x + c, 0.0, None))
    rms = float(np.sqrt(np.mean((predicted - np.sqrt(y)) ** 2)))
    return WorkingCurveFit(motion, spot, cutoff, nominal_spot, rms, tuple(points))


@dataclass(frozen=True)
class SpeedFactorFit:
    """ln v = ln P + β0 + Σ βj·xj fitted to a DOE table of fastest speeds."""

    names: tuple[str, ...]
    coefficients: np.ndarray      # β0, β1...
    predicted: np.ndarray         # mm/s per run
    rms_log_error: float
    free_power_exponent: float    # the exponent of P when it is fitted too (model: 1)

    def speed(self, power: float, levels: dict[str, float]) -> float:
        """Predicted fastest speed (mm/s) at `power` W and coded levels of the other factors."""
        unknown = set(self.names) - set(levels)
        if unknown:
            raise ProcessError(f"speed fit: levels missing for {', '.join(sorted(unknown))}")
        value = self.coefficients[0] + sum(b * levels[n] for n, b in zip(self.names,
                                                                          self.coefficients[1:]))
        return float(power * math.exp(value))


def fit_speed_factors(powers, speeds, levels: dict[str, list[float]]) -> SpeedFactorFit:
    """Fit the DOE table: per run the power (W), the fastest speed (mm/s) and the coded
    levels of the other factors by name."""
    p, v = np.asarray(powers, dtype=float), np.asarray(speeds, dtype=float)
    if p.shape != v.shape or p.ndim != 1 or len(p) < len(levels) + 2:
        raise ProcessError(f"speed fit: need one power and speed per run and more runs than "
                           f"factors (got {p.shape}, {v.shape}, {len(levels)} factors)")
    if np.any(p <= 0) or np.any(v <= 0):
        raise ProcessError("speed fit: powers and speeds must be > 0")
    names = tuple(levels)
    columns = [np.ones(len(p))] + [np.asarray(levels[n], dtype=float) for n in names]
    design = np.column_stack(columns)
    beta = np.linalg.lstsq(design, np.log(v) - np.log(p), rcond=None)[0]
    log_pred = design @ beta + np.log(p)
    free = np.linalg.lstsq(np.column_stack(columns + [np.log(p)]), np.log(v), rcond=None)[0]
    return SpeedFactorFit(names, beta, np.exp(log_pred),
                          float(np.sqrt(np.mean((log_pred - np.log(v)) ** 2))), float(free[-1]))

