"""Fluidic channels and chambers on a cylinder (METHODS section 1: base wall 0.5 mm with the
large tool, channel walls with the small tool, smallest gap 1.0 mm; X, Y, Z + A motions).

The layout is drawn in the cylinder's unrolled plane (x arc length, y axial; `patterns`
maps it exactly): the channel footprint is the outline of the whole device; `channels` are
the open gaps (shapely polygons) inside it. The base layer covers the footprint (zigzag);
the walls are the footprint minus the gaps, built up to `wall_height` in layers. Each part
gets its tool by curvature from the tool library (`process.selection.choose_tool`): the base
the largest tool that fits, the walls the largest that also resolves the narrowest wall or
gap; the toolpath changes tool between them.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np
from shapely.geometry import MultiPolygon, Polygon, box

from freecad_conformal.errors import PlanError
from freecad_conformal.geometry.faces import face_kind, smallest_radius
from freecad_conformal.paths.features.feeds import CureSetting
from freecad_conformal.paths.features.moves import TRAVEL_CLEARANCE
from freecad_conformal.paths.features.patterns import pattern_paths, patterns_toolpath
from freecad_conformal.paths.features.program import FeatureProgram
from freecad_conformal.paths.features.shells import check_tilt
from freecad_conformal.process.selection import choose_tool
from freecad_conformal.process.tools import Tool
from freecad_conformal.toolpath import ToolpathBuilder

#: METHODS: smallest channel gap 1.0 mm, base wall 0.5 mm.
MIN_GAP = 1.0
BASE_THICKNESS = 0.5

#: Widths found by `narrowest` are within this (mm) of the true width: GEOS drops the last
#: slivers of a negative buffer a few 1e-5 mm before they vanish.
WIDTH_TOLERANCE = 1e-4
#: Tilt (rad) standing in for zero on a flat face, where the curvature rules have no angle
#: to divide by.
FLAT_TILT = 1e-6


def straight_channels(count: int, length: float, gap: float, wall: float) -> tuple[Polygon, MultiPolygon]:
    """(footprint, gaps) of `count` parallel channels along x, `gap` wide, `wall` apart,
    with a wall all round."""
    if count < 1 or not (length > 0 and gap > 0 and wall > 0):
        raise PlanError(f"channels: need count >= 1 and positive length, gap, wall (got {count}, "
                        f"{length}, {gap}, {wall})")
    height = count * gap + (count + 1) * wall
    footprint = box(-length / 2 - wall, -height / 2, length / 2 + wall, height / 2)
    gaps = [box(-length / 2, -height / 2 + wall + k * (gap + wall),
                length / 2, -height / 2 + wall + k * (gap + wall) + gap) for k in range(count)]
    return footprint, MultiPolygon(gaps)


def narrowest(region) -> float:
    """Narrowest width of a region (mm): twice the largest inset that does not split or
    empty any part, found by bisection on negative buffers."""
    low, high = 0.0, max(region.bounds[2] - region.bounds[0], region.bounds[3] - region.bounds[1])
    parts = len(getattr(region, "geoms", [region]))
    for _ in range(40):
        mid = 0.5 * (low + high)
        inner = region.buffer(-mid)
        if inner.is_empty or len(getattr(inner, "geoms", [inner])) != parts:
            high = mid
        else:
            low = mid
    return 2.0 * low


@dataclass
class ChannelPlan:
    base_tool: Tool
    wall_tool: Tool
    builder: ToolpathBuilder
    explanation: str


def channels_toolpath(face, tools: list[Tool], footprint, gaps, wall_height: float,
                      layer: float, setting_for: Callable[[Tool, float, str], CureSetting],
                      base_thickness: float = BASE_THICKNESS, centre=None,
                      build_direction=(0, 0, 1), what: str = "channels",
                      program: FeatureProgram | None = None) -> ChannelPlan:
    """Base with the large tool, walls with the small one, on a cylinder face; the feed of
    each from `setting_for(tool, line width, what)` (the tool's curing fit)."""
    if face_kind(face) != "cylinder":
        raise PlanError(f"{what}: channels are built on a cylinder face, not a {face_kind(face)}")
    gap = narrowest(gaps)
    if gap < MIN_GAP - WIDTH_TOLERANCE:
        raise PlanError(f"{what}: the narrowest channel gap is {gap:.3g} mm, below the "
                        f"{MIN_GAP:g} mm the process resolves")
    walls = footprint.difference(gaps)
    wall_width = narrowest(walls)
    rs = smallest_radius(face)
    probe, _ = pattern_paths(face, footprint, wall_width, layer, layer, centre=centre, fill="zigzag",
                             what=what)
    tilt = check_tilt(np.vstack([p.axes for p in probe]), max(tools, key=lambda t: t.max_tilt),
                      build_direction, what)
    theta = max(tilt, FLAT_TILT)       # a flat face: the curvature rules decide alone
    base_choice = choose_tool(tools, rs, base_thickness, theta)
    wall_choice = choose_tool(tools, rs, layer, theta, resolution=min(wall_width, gap))
    for choice, part in ((base_choice, "base"), (wall_choice, "walls")):
        if choice.recommended is None:
            raise PlanError(f"{what}: no tool for the {part}: {choice.explanation()}")
    base_tool, wall_tool = base_choice.recommended, wall_choice.recommended
    program = program or FeatureProgram(what)
    lift = base_thickness + wall_height + TRAVEL_CLEARANCE
    base_width = base_tool.spec.min_line_width
    base_setting = setting_for(base_tool, base_width, f"{what} base")
    base_paths, _ = pattern_paths(face, footprint, base_width, base_thickness,
                                  base_thickness, centre=centre, fill="zigzag", what=f"{what} base")
    base_number = program.enter(base_tool, base_paths[0].points[0], base_paths[0].axes[0])
    program.cures(base_number, base_setting, "base lines", base_thickness)
    patterns_toolpath(base_paths, base_setting.feed, base_number,
                      program.power_fraction(base_number, base_setting), lift=lift,
                      builder=program.builder, face=face,
                      energy_per_mm=base_setting.energy_per_mm)
    last = base_paths[-1]
    program.last = (last.points[-1] + lift * last.axes[-1], last.axes[-1])
    width = min(wall_tool.spec.min_line_width * 2, wall_width)
    wall_setting = setting_for(wall_tool, width, f"{what} walls")
    wall_paths, _ = pattern_paths(face, walls, width, wall_height, layer, centre=centre,
                                  fill="contours", what=f"{what} walls")
    for path in wall_paths:                 # walls stand on the base
        path.points = path.points + base_thickness * path.axes
    wall_number = program.enter(wall_tool, wall_paths[0].points[0], wall_paths[0].axes[0])
    program.cures(wall_number, wall_setting, "wall lines", layer)
    patterns_toolpath(wall_paths, wall_setting.feed, wall_number,
                      program.power_fraction(wall_number, wall_setting), lift=lift,
                      builder=program.builder, face=face,
                      energy_per_mm=wall_setting.energy_per_mm)
    text = (f"base: {base_choice.explanation()}; walls (narrowest wall {wall_width:.3g} mm, "
            f"gap {gap:.3g} mm): {wall_choice.explanation()}; rs {rs:.4g} mm, tilt up to "
            f"{math.degrees(tilt):.1f}°")
    program.choices.append(text)
    end = wall_paths[-1]
    program.last = (end.points[-1] + lift * end.axes[-1], end.axes[-1])
    return ChannelPlan(base_tool, wall_tool, program.builder, text)
