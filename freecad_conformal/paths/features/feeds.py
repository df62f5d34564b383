"""Curing feeds from a tool's calibrated working curves (process/curing_fit.py).

A feature asks for a width (lines: patterns, shells, channels) or a diameter (rods); the
tool's settings for the resin hold the measured points the curves are fitted to, so the feed
is the one whose exposure cures that width at the tool's power. A feed given by the user
wins; the width it cures is then reported instead. Every cure segment carries its energy
per mm, P/v (J/mm), so program headers report the energy cured.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from freecad_conformal.errors import PlanError, ProcessError
from freecad_conformal.process.curing_fit import WorkingCurveFit, fit_working_curve
from freecad_conformal.process.process_settings import ProcessSettings
from freecad_conformal.process.tools import Tool
from freecad_conformal.tolerances import ROUNDING_SLACK

#: METHODS section 1: the machine's maximum speed Vmax = 3.556 mm/s (mm/min here).
MACHINE_MAX_FEED = 3.556 * 60.0
DEFAULT_MATERIAL = "resin"
_SECONDS_PER_MINUTE = 60.0


@dataclass(frozen=True)
class CureSetting:
    """One cure: feed (mm/min), the width it cures (mm), power (W) and where the feed came from."""

    feed: float
    width: float
    power: float
    source: str

    @property
    def energy_per_mm(self) -> float:
        """P/v in J/mm: the toolpath's `flow` for a cure segment."""
        return self.power / (self.feed / _SECONDS_PER_MINUTE)

    def describe(self, what: str) -> str:
        return (f"{what} {self.width:.3f} mm at {self.feed:.1f} mm/min "
                f"({self.feed / _SECONDS_PER_MINUTE:.3f} mm/s), {self.power:g} W, "
                f"{self.energy_per_mm:.3f} J/mm ({self.source})")


def material_settings(tool: Tool, material: str | None = None) -> tuple[str, ProcessSettings]:
    """(name, settings) of `material` (default 'resin', else the tool's first material)."""
    if material:
        if material not in tool.settings:
            known = ", ".join(sorted(tool.settings)) or "none"
            raise PlanError(f"tool {tool.id} has no settings for material {material!r} "
                            f"(known: {known})")
        return material, tool.settings[material]
    if DEFAULT_MATERIAL in tool.settings:
        return DEFAULT_MATERIAL, tool.settings[DEFAULT_MATERIAL]
    if tool.settings:
        name = sorted(tool.settings)[0]
        return name, tool.settings[name]
    return DEFAULT_MATERIAL, ProcessSettings()


def _power(tool: Tool, settings: ProcessSettings) -> float:
    if settings.power:
        return settings.power
    levels = getattr(tool.spec, "power_levels", None)
    if levels:
        return max(levels)
    raise PlanError(f"tool {tool.id}: no power in its settings or power levels")


def _spot(tool: Tool) -> float:
    return float(getattr(tool.spec, "spot_diameter", tool.diameter))


def line_fit(tool: Tool, material: str | None = None) -> WorkingCurveFit | None:
    """The line-curing fit of the tool and material, or None without calibration points."""
    _, settings = material_settings(tool, material)
    if not settings.line_points:
        return None
    try:
        return fit_working_curve(settings.line_points, _spot(tool), "line")
    except ProcessError as exc:
        raise PlanError(f"tool {tool.id}: {exc}") from None


def rod_fit(tool: Tool, material: str | None = None) -> WorkingCurveFit | None:
    """The point-curing fit; one rod point takes its cut-off from the line fit."""
    _, settings = material_settings(tool, material)
    if not settings.rod_points:
        return None
    lines = line_fit(tool, material)
    try:
        return fit_working_curve(settings.rod_points, _spot(tool), "point",
                                 lines.cutoff_per_watt if lines else None)
    except ProcessError as exc:
        raise PlanError(f"tool {tool.id}: {exc}") from None


def _setting(fit: WorkingCurveFit | None, tool: Tool, settings: ProcessSettings, width: float,
             feed: float | None, what: str, max_feed: float) -> CureSetting:
    power = _power(tool, settings)
    if feed:
        cured = fit.width(power, feed / _SECONDS_PER_MINUTE) if fit else width
        if fit and cured <= 0:
            raise PlanError(f"{what}: nothing cures at {feed:g} mm/min with {tool.id} at "
                            f"{power:g} W (cut-off {fit.cutoff_speed(power) * 60:.4g} mm/min)")
        return CureSetting(feed, cured, power, "feed given")
    if fit is None:
        if settings.feed:
            return CureSetting(settings.feed, width, power, f"{tool.id}'s feed, no calibration")
        raise PlanError(f"{what}: {tool.id} has neither calibration points nor a feed for "
                        "its material; give --feed")
    model_feed = fit.feed_for_width(power, width)
    if model_feed > max_feed:
        narrowest = fit.width(power, max_feed / _SECONDS_PER_MINUTE)
        raise PlanError(f"{what}: {width:g} mm needs {model_feed:.4g} mm/min, faster than "
                        f"{max_feed:g} mm/min; {tool.id} cures no narrower than "
                        f"{narrowest:.3g} mm at {power:g} W")
    return CureSetting(model_feed, width, power, f"{fit.motion} curing fit")


def line_setting(tool: Tool, width: float, feed: float | None = None,
                 material: str | None = None, max_feed: float = MACHINE_MAX_FEED,
                 what: str = "lines") -> CureSetting:
    """Feed for lines `width` mm wide (or the width a given `feed` cures)."""
    if not (width > 0 and math.isfinite(width)):
        raise PlanError(f"{what}: line width must be > 0 mm, got {width!r}")
    finest = getattr(tool.spec, "min_line_width", 0.0)
    if width < finest - ROUNDING_SLACK:
        raise PlanError(f"{what}: a {width:g} mm line is finer than {tool.id}'s finest "
                        f"({finest:g} mm)")
    _, settings = material_settings(tool, material)
    return _setting(line_fit(tool, material), tool, settings, width, feed, what, max_feed)


def rod_settings(tool: Tool, diameters, feed: float | None = None, material: str | None = None,
                 max_feed: float = MACHINE_MAX_FEED, what: str = "rods") -> list[CureSetting]:
    """One setting per rod diameter (a profile along the rod gives several)."""
    _, settings = material_settings(tool, material)
    fit = rod_fit(tool, material)
    out = []
    for diameter in diameters:
        if not (diameter > 0 and math.isfinite(diameter)):
            raise PlanError(f"{what}: rod diameter must be > 0 mm, got {diameter!r}")
        out.append(_setting(fit, tool, settings, float(diameter), feed, what, max_feed))
    return out
