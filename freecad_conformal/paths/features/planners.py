"""One feature on one face from a settings object (the `feature` command's namespace, or
anything with the same attributes): picks the generator by face kind and builds the toolpath.

`tool_of(settings, default_id)` and `feed_of(settings, tool)` are passed in so the caller
decides where tools come from (the library) and the default feeds.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from freecad_conformal.errors import GeometryError, PlanError
from freecad_conformal.geometry.faces import face_kind, parameters_of
from freecad_conformal.paths.features import channels, outlines, patterns, rods, shells
from freecad_conformal.toolpath import Toolpath, ToolpathBuilder


def plan_rods(s, face, what: str, tool_of, feed_of) -> Toolpath:
    """Rods normal to a sphere (rings round the pole) or a cylinder (rings along the axis)."""
    tool = tool_of(s, "uv_small")
    kind = face_kind(face)
    if kind not in ("sphere", "cylinder"):
        raise PlanError(f"{what}: rods need a sphere or cylinder face, not a {kind}")
    surface = face.Surface
    centre, axis = np.array(tuple(surface.Center)), np.array(tuple(surface.Axis))
    low, high = tool.reachable_tilt()
    if kind == "sphere":
        up = np.asarray(s.build_direction, dtype=float)
        layout = rods.sphere_layout(centre, up, surface.Radius, s.spacing, s.rod_diameter,
                                    s.rod_length, high, s.rings)
    elif kind == "cylinder":
        _, _, v0, v1 = face.ParameterRange
        layout = rods.cylinder_layout(centre, axis, surface.Radius, s.spacing, s.rod_diameter,
                                      s.rod_length, v0 + s.spacing / 2, v1 - s.spacing / 2)
        layout = _reachable(layout, np.asarray(s.build_direction, dtype=float), high, what)
    layout = _on_face(layout, face, what)
    rods.check_layout(layout, tool, what)
    curing = rods.PointCuring()
    builder = ToolpathBuilder(part=what, material="UV resin")
    builder.event("tool_change", tool=1)
    rods.rods_toolpath(layout, tool, curing, 1, s.diameter_profile, builder=builder)
    return builder.build()


def _subset(layout: rods.RodLayout, keep: np.ndarray) -> rods.RodLayout:
    layout.bases, layout.axes, layout.ring_of = layout.bases[keep], layout.axes[keep], layout.ring_of[keep]
    return layout


def _reachable(layout, up, high, what):
    tilt = np.arccos(np.clip(layout.axes @ (up / np.linalg.norm(up)), -1, 1))
    keep = tilt <= high + 1e-9
    if not keep.any():
        raise PlanError(f"{what}: no rod normal is within the tool's W {math.degrees(high):g}° "
                        "of the build direction")
    return _subset(layout, keep)


def _on_face(layout, face, what):
    uv = parameters_of(face, layout.bases)
    keep = np.array([face.isPartOfDomain(float(u), float(v)) for u, v in uv])
    if not keep.any():
        raise PlanError(f"{what}: no rod of the layout stands on the face")
    return _subset(layout, keep)


def plan_shell(s, face, what: str, tool_of, feed_of) -> Toolpath:
    tool = tool_of(s, "uv_large")
    feed = feed_of(s, tool)
    tilt = math.radians(s.tilt)
    low, high = tool.reachable_tilt()
    if abs(tilt) > high:
        raise PlanError(f"{what}: a tilt of {s.tilt:g}° from the normal is beyond the W "
                        f"{math.degrees(tool.max_tilt):g}° of {tool.id}")
    if s.cup_height:
        rings = shells.conical_cup(face, tool, s.cup_height, s.layer, feed, s.first_layer,
                                   build_direction=s.build_direction, what=what)
    else:
        width = s.width or tool.spec.min_line_width
        rings = shells.base_shell(face, tool, width, s.layers, s.layer, feed, tilt,
                                  s.build_direction, what)
    builder = ToolpathBuilder(part=what, material="UV resin")
    builder.event("tool_change", tool=1)
    return shells.rings_toolpath(rings, 1, builder=builder).build()


def outline_region(s, what: str):
    """The pattern's planar region from --svg, --text or --outline (exactly one)."""
    given = [name for name in ("svg", "text", "outline") if getattr(s, name, None)]
    if len(given) != 1:
        raise PlanError(f"{what}: give exactly one of --svg, --text, --outline (got {given or 'none'})")
    if s.svg:
        text = Path(s.svg).read_text(encoding="utf-8")
        if "<svg" in text:
            import re
            found = re.findall(r'\sd="([^"]+)"', text)
            if not found:
                raise GeometryError(f"{what}: SVG file {s.svg} has no <path d=...>")
            text = " ".join(found)
        return outlines.region_from_rings(outlines.svg_path_rings(text), f"{what} SVG outline")
    if s.text:
        return outlines.region_from_rings(outlines.text_rings(s.text, s.text_size), f"{what} text")
    from freecad_conformal.geometry.solids import load_shape
    return outlines.region_from_rings(outlines.wire_rings(load_shape(s.outline)
                                                          if not s.outline.lower().endswith(".brep")
                                                          else _read_brep(s.outline)), what)


def _read_brep(path: str):
    from freecad_conformal.freecad_env import import_freecad
    _, Part = import_freecad()
    return Part.read(path)


def facing_point(face, direction) -> tuple[float, float]:
    """(u, v) where the face's normal is closest to `direction` (the default pattern centre,
    where the tool needs the least tilt), on a grid over the face, at the v middle for
    surfaces of revolution."""
    from freecad_conformal.geometry.faces import domain_grid, normals_at
    grid = domain_grid(face, 48)
    up = np.asarray(direction, dtype=float) / np.linalg.norm(direction)
    best = grid[int(np.argmax(normals_at(face, grid) @ up))]
    if face_kind(face) in ("cylinder", "cone"):
        _, _, v0, v1 = face.ParameterRange
        return float(best[0]), 0.5 * (v0 + v1)
    return float(best[0]), float(best[1])


def plan_pattern(s, face, what: str, tool_of, feed_of) -> Toolpath:
    tool = tool_of(s, "uv_small")
    region = outline_region(s, what)
    width = s.width or tool.spec.min_line_width
    centre = tuple(s.at) if s.at else facing_point(face, s.build_direction)
    paths, _ = patterns.pattern_paths(face, region, width, s.height, s.layer, centre, s.fill,
                                      what=what)
    shells.check_tilt(np.vstack([p.axes for p in paths]), tool, s.build_direction, what)
    builder = ToolpathBuilder(part=what, material="UV resin")
    builder.event("tool_change", tool=1)
    return patterns.patterns_toolpath(paths, feed_of(s, tool), 1, builder=builder).build()


def plan_channels(s, face, what: str, tool_of, feed_of) -> Toolpath:
    from freecad_conformal.process.library import ToolLibrary
    tools = [t for t in ToolLibrary.load() if t.kind == "uv_light_guide"]
    footprint, gaps = channels.straight_channels(s.channels, s.channel_length, s.gap, s.wall)
    centre = tuple(s.at) if s.at else facing_point(face, s.build_direction)
    plan = channels.channels_toolpath(face, tools, footprint, gaps, s.wall_height, s.layer,
                                      feed_of(s, plan_tool(tools, "uv_large")),
                                      feed_of(s, plan_tool(tools, "uv_small")), centre=centre,
                                      build_direction=s.build_direction, what=what)
    return plan.builder.build()


def plan_tool(tools, tool_id: str):
    return next((t for t in tools if t.id == tool_id), tools[0])
