"""Line curing with a UV light guide: the stereolithography working curve (METHODS section 1).

    cure depth       Cd = Dp · ln(E / Ec)          (0 when E ≤ Ec: nothing cures)
    line width       Lw = B · sqrt(Cd / (2·Dp))    (B the spot diameter)

Units: lengths mm, power W, feed mm/min, exposure mJ/cm² (the unit of resin datasheets).

METHODS gives the two formulas but not how exposure follows from power, spot and speed. The
width formula is the Gaussian-beam result (B the 1/e² diameter), so the default exposure is
the Gaussian line's peak exposure E = sqrt(2/π)·P / (W0·v), W0 = B/2. A flat-top spot (a
bare fibre end) gives E = 4·P / (π·B·v) on the line centre (`profile="top_hat"`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from freecad_conformal.errors import ProcessError

PROFILES = ("gaussian", "top_hat")
#: J/mm² -> mJ/cm²: 1 J = 1e3 mJ and 1 mm² = 1e-2 cm².
_J_PER_MM2_TO_MJ_PER_CM2 = 1e5
_SECONDS_PER_MINUTE = 60.0


def _positive(value: float, name: str) -> None:
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
        raise ProcessError(f"curing model: {name} must be a positive number, got {value!r}")


def cure_depth(exposure: float, dp: float, ec: float) -> float:
    """Cd = Dp·ln(E/Ec) in mm; 0 when the exposure does not reach the critical exposure."""
    _positive(dp, "penetration depth Dp")
    _positive(ec, "critical exposure Ec")
    if exposure < 0 or not math.isfinite(exposure):
        raise ProcessError(f"curing model: exposure must be >= 0, got {exposure!r}")
    return dp * math.log(exposure / ec) if exposure > ec else 0.0


def exposure_for_depth(depth: float, dp: float, ec: float) -> float:
    """The exposure (mJ/cm²) that cures to `depth` mm: E = Ec·exp(Cd/Dp)."""
    _positive(dp, "penetration depth Dp")
    _positive(ec, "critical exposure Ec")
    if depth < 0:
        raise ProcessError(f"curing model: cure depth must be >= 0, got {depth!r}")
    return ec * math.exp(depth / dp)


def line_width(depth: float, spot_diameter: float, dp: float) -> float:
    """Lw = B·sqrt(Cd/(2·Dp)) in mm."""
    _positive(spot_diameter, "spot diameter B")
    _positive(dp, "penetration depth Dp")
    if depth < 0:
        raise ProcessError(f"curing model: cure depth must be >= 0, got {depth!r}")
    return spot_diameter * math.sqrt(depth / (2.0 * dp))


def depth_for_line_width(width: float, spot_diameter: float, dp: float) -> float:
    """Inverse of `line_width`: Cd = 2·Dp·(Lw/B)²."""
    _positive(spot_diameter, "spot diameter B")
    _positive(dp, "penetration depth Dp")
    return 2.0 * dp * (width / spot_diameter) ** 2


def exposure_speed_product(power: float, spot_diameter: float, profile: str) -> float:
    """E·v (mJ/cm² · mm/s): the exposure of a line is this divided by the speed."""
    _positive(power, "power")
    _positive(spot_diameter, "spot diameter B")
    if profile == "gaussian":
        joules_per_mm = math.sqrt(2.0 / math.pi) * power / (spot_diameter / 2.0)
    elif profile == "top_hat":
        joules_per_mm = 4.0 * power / (math.pi * spot_diameter)
    else:
        raise ProcessError(f"curing model: profile must be one of {', '.join(PROFILES)}, "
                           f"got {profile!r}")
    return joules_per_mm * _J_PER_MM2_TO_MJ_PER_CM2


def line_exposure(power: float, spot_diameter: float, feed: float,
                  profile: str = "gaussian") -> float:
    """Exposure (mJ/cm²) on the centre of a line drawn at `feed` mm/min."""
    _positive(feed, "feed")
    return exposure_speed_product(power, spot_diameter, profile) / (feed / _SECONDS_PER_MINUTE)


def minimum_line_width(spot_diameter: float, dp: float, min_depth: float) -> float:
    """The narrowest line that still cures `min_depth` deep (enough to bond to the layer
    below); narrower lines need a smaller spot, not a faster feed."""
    return line_width(min_depth, spot_diameter, dp)


@dataclass(frozen=True)
class LineCuring:
    """One tool/resin/power combination: widths versus feed and the feeds for a width."""

    power: float
    spot_diameter: float
    dp: float
    ec: float
    profile: str = "gaussian"

    def exposure(self, feed: float) -> float:
        return line_exposure(self.power, self.spot_diameter, feed, self.profile)

    def depth(self, feed: float) -> float:
        return cure_depth(self.exposure(feed), self.dp, self.ec)

    def width(self, feed: float) -> float:
        """Line width (mm) at `feed` mm/min; 0 at or above `max_feed` (nothing cures)."""
        return line_width(self.depth(feed), self.spot_diameter, self.dp)

    def widths(self, feeds: np.ndarray) -> np.ndarray:
        """Line width for each feed (the line-width-versus-speed curve)."""
        return np.array([self.width(float(f)) for f in np.asarray(feeds, dtype=float).ravel()])

    def max_feed(self) -> float:
        """The feed (mm/min) at which the exposure falls to Ec: faster lines do not cure."""
        _positive(self.ec, "critical exposure Ec")
        speed = exposure_speed_product(self.power, self.spot_diameter, self.profile) / self.ec
        return speed * _SECONDS_PER_MINUTE

    def feed_for_width(self, width: float) -> float:
        """The feed (mm/min) that cures a line `width` mm wide."""
        _positive(width, "line width")
        exposure = exposure_for_depth(depth_for_line_width(width, self.spot_diameter, self.dp),
                                      self.dp, self.ec)
        speed = exposure_speed_product(self.power, self.spot_diameter, self.profile) / exposure
        return speed * _SECONDS_PER_MINUTE
