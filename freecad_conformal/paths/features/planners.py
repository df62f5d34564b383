"""One feature on one face from a settings object (validated values of settings/feature.py):
picks the generator by face kind, the tool (given, or by curvature), the feeds from the
tool's curing fits, and builds the checked toolpath (paths/features/program.py).

`part` is the solid the face belongs to: every move is checked against it (and against what
the program builds); without it the face alone stands for the part.
"""
from __future__ import annotations

import math

import numpy as np

from freecad_conformal.errors import PlanError
from freecad_conformal.geometry.faces import face_kind, parameters_of
from freecad_conformal.paths.features import (
    channels, clearance, feeds, patterns, rods, shells, texture)
from freecad_conformal.paths.features.choice import choose_for_face
from freecad_conformal.paths.features.centre import pattern_centre
from freecad_conformal.paths.features.moves import TRAVEL_CLEARANCE, approach, retract, travel
from freecad_conformal.paths.features.outline_source import outline_region
from freecad_conformal.paths.features.program import FeatureProgram
from freecad_conformal.process.library import ToolLibrary
from freecad_conformal.process.tools import Tool
from freecad_conformal.toolpath import Toolpath
from freecad_conformal.tolerances import LIMIT_SLACK

#: Tools used when none is given and no choice by curvature applies.
DEFAULT_TOOLS = {"rods": "uv_small", "cup": "uv_large"}


def _uv_tools(library: ToolLibrary) -> list[Tool]:
    """Light guides that draw lines (masked tools stamp textures only)."""
    return [t for t in library if t.kind == "uv_light_guide" and getattr(t.spec, "mask", None) is None]


def _part_points(part, face) -> np.ndarray:
    return clearance.part_samples(part if part is not None else face)


def _done(program: FeatureProgram, owned: bool, part, face, rule: str,
          check_part: bool = True) -> Toolpath | None:
    """Finish a program this planner started; one shared with others is finished by its owner."""
    if not owned:
        return None
    return program.finish(_part_points(part, face) if check_part else None, rule)


def _chosen(s, library: ToolLibrary, program: FeatureProgram, face, cd: float,
            resolution: float | None, what: str, axes: np.ndarray | None = None) -> Tool:
    """The tool given by --tool, else the one the curvature rules choose for the face (the
    tilt from the feature's own tool `axes` when known, else the whole face's normals)."""
    if s.tool:
        return library.get(s.tool)
    choice = choose_for_face(face, _uv_tools(library), cd, resolution, s.build_direction,
                             axes=axes, what=what)
    program.choices.append(choice.reason)
    return choice.tool


def plan_rods(s, face, what: str, part=None, library: ToolLibrary | None = None,
              program: FeatureProgram | None = None) -> Toolpath | None:
    """Rods normal to a sphere (rings round the pole) or a cylinder (rings along the axis)."""
    library = library or ToolLibrary.load()
    tool = library.get(s.tool or DEFAULT_TOOLS["rods"])
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
    else:
        _, _, v0, v1 = face.ParameterRange
        layout = rods.cylinder_layout(centre, axis, surface.Radius, s.spacing, s.rod_diameter,
                                      s.rod_length, v0 + s.spacing / 2, v1 - s.spacing / 2)
        layout = _reachable(layout, np.asarray(s.build_direction, dtype=float), high, what)
    layout = _on_face(layout, face, what)
    if s.collision_rule == "published":
        _published_rule(layout, tool, what)
    else:
        rods.check_layout(layout, tool, what)
    program, owned = (FeatureProgram(what), True) if program is None else (program, False)
    number = program.enter(tool, layout.bases[0], layout.axes[0])
    settings = feeds.rod_settings(tool, s.diameter_profile or [s.rod_diameter], s.feed,
                                  what=what)
    for setting in dict.fromkeys(settings):
        program.cures(number, setting, "rod")
    rods.rods_toolpath(layout, tool, settings, number, builder=program.builder,
                       max_power=max(getattr(tool.spec, "power_levels", None) or [settings[0].power]))
    program.last = (layout.bases[-1] + (layout.length + rods.CLEARANCE) * layout.axes[-1],
                    layout.axes[-1])
    return _done(program, owned, part, face, s.collision_rule)


def _published_rule(layout: rods.RodLayout, tool: Tool, what: str) -> None:
    """Rule (i): the angle between neighbouring rods at least the published minimum."""
    head = tool.envelope.body_diameter
    need = rods.published_min_angle(layout.diameter, layout.radius, layout.length, head)
    have = layout.angle if layout.surface == "sphere" else min(layout.angle,
                                                                layout.spacing / layout.radius)
    if have < need:
        raise PlanError(f"{what}: rule (i) needs {math.degrees(need):.2f}° between rods for a "
                        f"{head:g} mm head, the layout has {math.degrees(have):.2f}° (d "
                        f"{layout.spacing:g} mm); space the rods further apart")


def _subset(layout: rods.RodLayout, keep: np.ndarray) -> rods.RodLayout:
    layout.bases, layout.axes, layout.ring_of = layout.bases[keep], layout.axes[keep], layout.ring_of[keep]
    return layout


def _reachable(layout, up, high, what):
    tilt = np.arccos(np.clip(layout.axes @ (up / np.linalg.norm(up)), -1, 1))
    keep = tilt <= high + LIMIT_SLACK
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


def plan_shell(s, face, what: str, part=None, library: ToolLibrary | None = None,
               program: FeatureProgram | None = None) -> Toolpath | None:
    """Rings by rotation on a sphere/cylinder/cone face, or an inverse conical cup."""
    library = library or ToolLibrary.load()
    program, owned = (FeatureProgram(what), True) if program is None else (program, False)
    if s.cup_height:
        tool = library.get(s.tool or DEFAULT_TOOLS["cup"])
    else:
        tool = _chosen(s, library, program, face, s.layer, s.width, what)
    tilt = math.radians(s.tilt)
    low, high = tool.reachable_tilt()
    if abs(tilt) > high:
        raise PlanError(f"{what}: a tilt of {s.tilt:g}° from the normal is beyond the W "
                        f"{math.degrees(tool.max_tilt):g}° of {tool.id}")
    _, process = feeds.material_settings(tool)
    width = s.width or (process.width if s.cup_height and process.width else None) \
        or tool.spec.min_line_width
    setting = feeds.line_setting(tool, width, s.feed, what=what)
    if s.cup_height:
        first = feeds.line_setting(tool, width, setting.feed * shells.FIRST_LAYER_FEED_FACTOR,
                                   what=f"{what} first layer")
        rings = shells.conical_cup(face, tool, s.cup_height, s.layer, setting.feed, s.first_layer,
                                   first_feed=first.feed, build_direction=s.build_direction,
                                   what=what, width=width)
        travel_face, lift = None, TRAVEL_CLEARANCE
    else:
        rings = shells.base_shell(face, tool, width, s.layers, s.layer, setting.feed, tilt,
                                  s.build_direction, what)
        travel_face = face
        lift = s.layers * s.layer + TRAVEL_CLEARANCE
    number = program.enter(tool, rings[0].points[0], rings[0].axes[0])
    program.cures(number, setting, "wall" if s.cup_height else "ring", s.layer)
    if s.cup_height:
        program.cures(number, first, "first layer", s.first_layer)
    shells.rings_toolpath(rings, number, program.power_fraction(number, setting), lift=lift,
                          builder=program.builder, face=travel_face, power_w=setting.power)
    program.last = (rings[-1].points[-1] + lift * rings[-1].axes[-1], rings[-1].axes[-1])
    # the cup is the part being built: only what the program cures can be hit
    return _done(program, owned, part, face, s.collision_rule, check_part=not s.cup_height)


def plan_pattern(s, face, what: str, part=None, library: ToolLibrary | None = None,
                 program: FeatureProgram | None = None) -> Toolpath | None:
    library = library or ToolLibrary.load()
    program, owned = (FeatureProgram(what), True) if program is None else (program, False)
    region = outline_region(s, what)
    centre = pattern_centre(face, s.at, s.at_point, s.build_direction, what)
    finest = min(t.spec.min_line_width for t in _uv_tools(library))
    probe_width = s.width or finest
    paths, _ = patterns.pattern_paths(face, region, probe_width, s.height, s.layer, centre,
                                      s.fill, what=what)
    tool = _chosen(s, library, program, face, s.layer, probe_width, what,
                   axes=np.vstack([p.axes for p in paths]))
    width = s.width or tool.spec.min_line_width
    if width != probe_width:
        paths, _ = patterns.pattern_paths(face, region, width, s.height, s.layer, centre, s.fill,
                                          what=what)
    setting = feeds.line_setting(tool, width, s.feed, what=what)
    shells.check_tilt(np.vstack([p.axes for p in paths]), tool, s.build_direction, what)
    number = program.enter(tool, paths[0].points[0], paths[0].axes[0])
    program.cures(number, setting, "lines", s.layer)
    patterns.patterns_toolpath(paths, setting.feed, number, program.power_fraction(number, setting),
                               lift=s.height + TRAVEL_CLEARANCE, builder=program.builder,
                               face=face, energy_per_mm=setting.energy_per_mm)
    lift = s.height + TRAVEL_CLEARANCE
    program.last = (paths[-1].points[-1] + lift * paths[-1].axes[-1], paths[-1].axes[-1])
    return _done(program, owned, part, face, s.collision_rule)


def plan_channels(s, face, what: str, part=None, library: ToolLibrary | None = None,
                  program: FeatureProgram | None = None) -> Toolpath | None:
    library = library or ToolLibrary.load()
    tools = _uv_tools(library)
    footprint, gaps = channels.straight_channels(s.channels, s.channel_length, s.gap, s.wall)
    centre = pattern_centre(face, s.at, s.at_point, s.build_direction, what)
    program, owned = (FeatureProgram(what), True) if program is None else (program, False)

    def setting_for(tool: Tool, width: float, part_what: str) -> feeds.CureSetting:
        return feeds.line_setting(tool, width, s.feed, what=part_what)

    channels.channels_toolpath(face, tools, footprint, gaps, s.wall_height, s.layer, setting_for,
                               centre=centre, build_direction=s.build_direction, what=what,
                               program=program)
    return _done(program, owned, part, face, s.collision_rule)


def plan_texture(s, face, what: str, part=None, library: ToolLibrary | None = None,
                 program: FeatureProgram | None = None) -> Toolpath | None:
    """A masked tool's shape stamped on a grid or along a curve (paths/features/texture.py)."""
    library = library or ToolLibrary.load()
    tool = library.get(s.tool or "uv_mask_disk")
    mask = texture.masked(tool, what)
    _, process = feeds.material_settings(tool)
    power = process.power or max(getattr(tool.spec, "power_levels", None) or [0.0])
    if not power > 0:
        raise PlanError(f"{what}: {tool.id} has no power in its settings")
    centre = pattern_centre(face, s.at, s.at_point, s.build_direction, what)
    stamps = texture.stamp_positions(face, centre, s.layout, s.pitch, s.extent, what)
    shells.check_tilt(stamps.normals, tool, s.build_direction, what)
    program, owned = (FeatureProgram(what), True) if program is None else (program, False)
    number = program.enter(tool, stamps.points[0], stamps.normals[0])
    builder, lift = program.builder, s.thickness + TRAVEL_CLEARANCE
    fraction = min(power / max(getattr(tool.spec, "power_levels", None) or [power]), 1.0)
    if s.stamp == "dwell":
        seconds = texture.dwell_seconds(s.thickness, mask, power, process.dp, process.ec, tool.id)
        program.notes.append(f"T{number} {tool.id}: {mask.shape} stamps {s.thickness:g} mm thick "
                             f"by a {seconds:.3g} s dwell each at {power:g} W "
                             f"({power * seconds:.3g} J per stamp)")
    else:
        feed = s.feed or process.feed
        if not feed:
            raise PlanError(f"{what}: {tool.id} has no stamping feed for its resin; give --feed")
        setting = feeds.CureSetting(feed, mask.size, power, "stamping feed")
        program.cures(number, setting, f"{mask.shape} stamps {s.thickness:g} mm thick,")
    previous, previous_axis = stamps.points[0], stamps.normals[0]
    for k, (point, normal) in enumerate(zip(stamps.points, stamps.normals)):
        start = point + (s.thickness if s.stamp == "dwell" else 0.0) * normal
        if k == 0:
            approach(builder, start, normal, lift, 600.0, number)
        else:
            travel(builder, face, previous, previous_axis, start, normal, lift, 600.0, number)
        builder.event("light_on", power=fraction)
        if s.stamp == "dwell":
            builder.event("dwell", seconds=seconds)
            previous = start
        else:
            previous = point + s.thickness * normal
            builder.add_segment([point, previous], axes=normal, kind="cure", feed=setting.feed,
                                tool=number, flow=setting.energy_per_mm)
        builder.event("light_off")
        previous_axis = normal
    retract(builder, previous, previous_axis, lift, 600.0, number)
    program.last = (previous + lift * previous_axis, previous_axis)
    return _done(program, owned, part, face, s.collision_rule)


PLANNERS = {"rods": plan_rods, "shell": plan_shell, "pattern": plan_pattern,
            "channels": plan_channels, "texture": plan_texture}


def plan_sequence(features, part, what: str = "features", rule: str = "envelope",
                  library: ToolLibrary | None = None) -> Toolpath:
    """Several features of one part in one program, in order: `features` are (settings,
    face, kind, what) tuples. Tool changes are inserted where the tool changes (the tool
    retracts home first), and every move of the whole program is checked against the part
    and everything built before it."""
    library = library or ToolLibrary.load()
    program = FeatureProgram(what)
    cup = False
    for s, face, kind, name in features:
        if kind not in PLANNERS:
            raise PlanError(f"{name}: unknown feature kind {kind!r}")
        PLANNERS[kind](s, face, name, part, library, program=program)
        cup = cup or (kind == "shell" and bool(s.cup_height))
    # a cup is the part being built, so a program holding one is checked against itself only
    return program.finish(None if cup else _part_points(part, None), rule)
