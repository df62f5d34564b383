"""Tool choice by curvature (METHODS section 1).

A straight cylindrical tool of diameter dt curing to depth cd on a surface whose smallest
radius of curvature is rs, at rotation θ, fits when

    dt ≤ 2·sqrt(cd·(2·rs − cd))     (it reaches depth cd inside the curve)
    dt ≤ 2·(rs − cd)·sin θ          (it fits at rotation θ)

and when θ is a tilt the tool reaches: [0, W] for a straight head, [bend − W, bend + W] for
an angled one, so an angled tool is chosen where θ exceeds a straight tool's W. The
recommended tool is the largest (fastest) that fits and resolves the feature size asked.
The formulas are applied as published; note that the second one rejects every tool at θ = 0.
A flat surface (rs = inf) puts no limit on dt.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Iterable

from freecad_conformal.errors import ProcessError
from freecad_conformal.process.tools import Tool

#: Tilt comparisons allow this much (rad, ~0.0006°) so a θ typed as exactly W still fits.
TILT_TOLERANCE = 1e-5


@dataclass
class ToolChoice:
    """Result of `choose_tool`: tools that fit, the recommended one, and why others do not."""

    fitting: list[Tool]
    recommended: Tool | None
    reasons: dict[str, str] = field(default_factory=dict)
    reach_limit: float = math.inf   # 2·sqrt(cd(2rs − cd))
    rotation_limit: float = math.inf  # 2(rs − cd)·sin θ

    def explanation(self) -> str:
        """One text for the user: the recommendation, or why nothing fits."""
        if self.recommended is not None:
            return (f"recommended {self.recommended.id} (dt {self.recommended.diameter:g} mm); "
                    f"tools fitting: {', '.join(t.id for t in self.fitting)}")
        limit = min(self.reach_limit, self.rotation_limit)
        if self.fitting:
            head = "tools fit, but none resolves the feature width asked"
        else:
            head = "no tool fits" + (f": need dt <= {limit:.4g} mm" if math.isfinite(limit) else "")
        lines = [head]
        lines += [f"  {tool_id}: {why}" for tool_id, why in sorted(self.reasons.items())]
        return "\n".join(lines)


def diameter_limits(rs: float, cd: float, theta: float) -> tuple[float, float]:
    """(reach limit, rotation limit) on dt for radius rs, curing depth cd, rotation θ (rad)."""
    if not (rs > 0):
        raise ProcessError(f"tool choice: smallest radius of curvature rs must be > 0 mm, got {rs!r}")
    if not (cd > 0 and math.isfinite(cd)):
        raise ProcessError(f"tool choice: curing depth cd must be > 0 mm, got {cd!r}")
    if not (0 <= theta <= math.pi and math.isfinite(theta)):
        raise ProcessError(f"tool choice: rotation θ must be within [0, π] rad, got {theta!r}")
    if math.isinf(rs):
        return math.inf, math.inf
    if cd >= rs:
        raise ProcessError(f"tool choice: curing depth cd {cd:g} mm must be smaller than the "
                           f"radius of curvature rs {rs:g} mm")
    return 2.0 * math.sqrt(cd * (2.0 * rs - cd)), 2.0 * (rs - cd) * math.sin(theta)


def choose_tool(tools: Iterable[Tool], rs: float, cd: float, theta: float,
                resolution: float | None = None, kind: str | None = "uv_light_guide") -> ToolChoice:
    """Tools that fit a surface of smallest radius `rs` (mm; math.inf for flat) at curing
    depth `cd` (mm) and rotation `theta` (rad), and the recommended one.

    `resolution` is the finest feature width asked (mm): a tool resolves it when its smallest
    line (UV `min_line_width`, else its diameter) is not wider. Masked tools (textures) are
    never chosen for lines. `kind` filters the tools
    (None keeps all kinds). Raises ProcessError on impossible inputs, never when nothing fits.
    """
    reach, rotation = diameter_limits(rs, cd, theta)
    if resolution is not None and not resolution > 0:
        raise ProcessError(f"tool choice: resolution must be > 0 mm, got {resolution!r}")
    fitting: list[Tool] = []
    reasons: dict[str, str] = {}
    for tool in tools:
        if kind is not None and tool.kind != kind:
            continue
        if getattr(tool.spec, "mask", None) is not None:
            reasons[tool.id] = "masked tip: it stamps its mask's shape, it does not draw lines"
            continue
        low, high = tool.reachable_tilt()
        if theta > high + TILT_TOLERANCE or theta < low - TILT_TOLERANCE:
            head = (f"angled {math.degrees(tool.bend_angle):g}° head"
                    if tool.head == "angled" else "straight head")
            reasons[tool.id] = (f"rotation {math.degrees(theta):.1f}° outside the "
                                f"{math.degrees(low):.1f}°..{math.degrees(high):.1f}° its {head} "
                                f"reaches (W {math.degrees(tool.max_tilt):g}°)")
        elif tool.diameter > reach:
            reasons[tool.id] = (f"dt {tool.diameter:g} mm > 2·sqrt(cd(2rs − cd)) = {reach:.4g} mm: "
                                "cannot reach the curing depth inside the curve")
        elif tool.diameter > rotation:
            reasons[tool.id] = (f"dt {tool.diameter:g} mm > 2(rs − cd)·sin θ = {rotation:.4g} mm: "
                                "does not fit at this rotation")
        elif resolution is not None and _finest_line(tool) > resolution:
            reasons[tool.id] = (f"finest line {_finest_line(tool):g} mm is wider than the "
                                f"resolution asked, {resolution:g} mm")
            fitting.append(tool)
        else:
            fitting.append(tool)
    resolving = [t for t in fitting if t.id not in reasons]
    # a V-bit's diameter is its shank's: at equal diameters the straight cutter works wider
    recommended = max(resolving, key=lambda t: (t.diameter, t.head == "straight",
                                                not getattr(t.spec, "taper_deg", 0.0), t.id),
                      default=None)
    fitting.sort(key=lambda t: (-t.diameter, t.id))
    return ToolChoice(fitting, recommended, reasons, reach, rotation)


def _finest_line(tool: Tool) -> float:
    return getattr(tool.spec, "min_line_width", tool.diameter)
