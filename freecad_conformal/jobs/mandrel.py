"""Builds on a rotating mandrel (METHODS section 5): cylindrical layers planned unrolled.

The part grows outward around a cylinder spinning about the machine's rotary axis. Layer i
is the exact cylindrical section of the solid at the mid-layer radius r_m + (i + ½)·h
(`geometry.cylindrical`), unrolled into the plane (arc length s, axial a); pieces cut apart
by the cylinder's seam are joined again across it (one period 2πr), the region is
zigzag-filled in the plane with lines along its long axis (for a helical band of pitch t
on radius r that is the band inclination α = atan(t / (2πr))), and the lines are rolled back
onto the nozzle radius r_m + (i + 1)·h with the nozzle along the outward radius.

A straight line of the unrolled plane is a move in which the axial position and the mandrel
angle both change linearly: the toolpath marks it "joint_linear" so the post-processor
writes it as one block (a five-turn helix is one G1).

Two outputs:
- true rotary axis: the toolpath goes through the post-processor for the machine (A in
  degrees);
- rotation mapped to a linear axis scaled at the first-layer radius R0 (Marlin in Cartesian
  mode): Y = R0·θ. A move of Lx (axial) and Ly (around, in Y mm) at layer radius Ri then
  needs M = K·sqrt((Ri/R0·Ly)² + Lx²) of extrusion (K the extrusion per mm) and, for the
  surface speed v, F = v·sqrt(Lx² + Ly²) / sqrt(Lx² + (Ri/R0·Ly)²); in the first layer
  Ri = R0 and nothing changes.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np
from shapely import affinity
from shapely.geometry import Polygon

from freecad_conformal.errors import PlanError
from freecad_conformal.paths.features.fill import as_region, long_axis_angle, zigzag
from freecad_conformal.settings.mandrel import PRINT_FEED, TRAVEL_FEED
from freecad_conformal.toolpath import Toolpath, ToolpathBuilder
from freecad_conformal.tolerances import DEFAULT_LINEAR_TOLERANCE

#: Radial lift (mm) for travel moves inside a layer, so the nozzle does not drag over beads.
TRAVEL_LIFT = 1.0

#: Pieces of a section closer than this (mm) across the seam belong together: the seam cut
#: leaves the two halves touching along a line, up to the section's chord tolerance.
SEAM_GAP = 1e-3


def band_inclination(pitch: float, radius: float) -> float:
    """α = atan(t / (2πr)) (rad): inclination of a helical band of pitch t on radius r."""
    if not (pitch > 0 and radius > 0):
        raise PlanError(f"helix: pitch {pitch!r} and radius {radius!r} must both be > 0 mm")
    return math.atan(pitch / (2.0 * math.pi * radius))


def compensated_extrusion(lx: np.ndarray | float, ly: np.ndarray | float, radius: float,
                          first_radius: float, k: float) -> np.ndarray | float:
    """M = K·sqrt((Ri/R0·Ly)² + Lx²): extrusion for a move of Lx axial, Ly around (Y mm at R0)."""
    if not (radius > 0 and first_radius > 0):
        raise PlanError(f"radii must be > 0 mm (layer {radius!r}, first layer {first_radius!r})")
    scale = radius / first_radius
    return k * np.sqrt((scale * np.asarray(ly)) ** 2 + np.asarray(lx) ** 2)


def corrected_feed(lx: np.ndarray | float, ly: np.ndarray | float, radius: float,
                   first_radius: float, surface_feed: float) -> np.ndarray | float:
    """Feed (Y mm/min) that moves the nozzle over the surface at `surface_feed` when Y is the
    rotation scaled at R0: v·|(Lx, Ly)| / |(Lx, Ri/R0·Ly)|."""
    scale = radius / first_radius
    lx, ly = np.asarray(lx, dtype=float), np.asarray(ly, dtype=float)
    commanded = np.hypot(lx, ly)
    true = np.hypot(lx, scale * ly)
    return surface_feed * np.divide(commanded, true, out=np.ones_like(true), where=true > 0)


@dataclass
class MandrelAxis:
    """The mandrel axis (a point and unit direction) and the frame angles are measured in."""

    point: np.ndarray
    direction: np.ndarray
    u: np.ndarray
    v: np.ndarray

    @classmethod
    def make(cls, point, direction) -> "MandrelAxis":
        from freecad_conformal.geometry.frames import LayerFrame
        frame = LayerFrame.for_direction(direction)
        return cls(np.asarray(point, dtype=float), frame.n, frame.u, frame.v)



@dataclass
class MandrelLayer:
    """One cylindrical layer: section radius, nozzle radius and its lines in (θ, axial)."""

    index: int
    section_radius: float
    nozzle_radius: float
    angle: float                                  # raster direction in the unrolled plane
    lines: list[np.ndarray] = field(repr=False)   # (N, 2) polylines of (θ rad, axial mm)

    def unrolled_length(self) -> float:
        """Path length on the nozzle cylinder (mm)."""
        total = 0.0
        for line in self.lines:
            step = np.diff(line, axis=0)
            total += float(np.hypot(step[:, 0] * self.nozzle_radius, step[:, 1]).sum())
        return total


def stitch_across_seam(polygons: list[Polygon], period: float) -> list[Polygon]:
    """Join pieces a cylinder's seam cut apart: shift a piece by ±period where it then
    touches another along a line, and merge, until nothing more joins."""
    pieces = [p for p in polygons if not p.is_empty]
    merged = True
    while merged and len(pieces) > 1:
        merged = False
        for i in range(len(pieces)):
            for j in range(len(pieces)):
                if i == j:
                    continue
                shifted = affinity.translate(pieces[j], xoff=period)
                contact = pieces[i].buffer(SEAM_GAP).intersection(shifted.buffer(SEAM_GAP))
                if contact.area > 4 * SEAM_GAP * SEAM_GAP * 10:
                    union = as_region([pieces[i].buffer(SEAM_GAP), shifted.buffer(SEAM_GAP)])
                    pieces[i] = union.buffer(-SEAM_GAP)
                    del pieces[j]
                    merged = True
                    break
            if merged:
                break
    return pieces


def spring_solid(inner_radius: float = 10.0, pitch: float = 8.0, turns: float = 5.0,
                 radial: float = 3.0, axial: float = 3.0):
    """A helical spring of rectangular section around the X axis (the mandrel of the
    rotary_mandrel machine): inner radius r, pitch t, `radial` × `axial` section, from x = 0."""
    App, Part = _freecad()
    if not (inner_radius > 0 and pitch > axial > 0 and turns > 0 and radial > 0):
        raise PlanError(f"spring: need radius > 0, pitch > axial section > 0, turns > 0 "
                        f"(got r {inner_radius}, t {pitch}, section {radial} x {axial}, {turns} turns)")
    helix = Part.makeHelix(pitch, pitch * turns, inner_radius)
    r, w, h = inner_radius, radial, axial
    corners = [App.Vector(r, 0, 0), App.Vector(r + w, 0, 0), App.Vector(r + w, 0, h),
               App.Vector(r, 0, h), App.Vector(r, 0, 0)]
    solid = Part.Wire(helix).makePipeShell([Part.Wire(Part.makePolygon(corners))], True, True)
    solid.rotate(App.Vector(0, 0, 0), App.Vector(0, 1, 0), 90)     # helix axis Z -> X
    return solid


def mandrel_radius(shape, axis: MandrelAxis) -> tuple[float, float]:
    """(inner, outer bound) radial distance of the part from the mandrel axis (mm)."""
    App, Part = _freecad()
    box = shape.BoundBox
    reach = box.DiagonalLength + float(np.linalg.norm(
        np.array([box.Center.x, box.Center.y, box.Center.z]) - axis.point))
    line = Part.makeLine(App.Vector(*(axis.point - reach * axis.direction)),
                         App.Vector(*(axis.point + reach * axis.direction)))
    inner = float(shape.distToShape(line)[0])
    corners = np.array([[x, y, z] for x in (box.XMin, box.XMax) for y in (box.YMin, box.YMax)
                        for z in (box.ZMin, box.ZMax)]) - axis.point
    radial = corners - np.outer(corners @ axis.direction, axis.direction)
    outer = float(np.linalg.norm(radial, axis=1).max())
    if inner <= 0.0:
        raise PlanError("the part touches or crosses the mandrel axis: nothing to build it "
                        "around (is the part placed on the machine's rotary axis?)")
    return inner, outer


def mandrel_layers(shape, axis: MandrelAxis, layer: float, width: float,
                   angle: float | None = None, inner: float | None = None,
                   progress: Callable[[int, int], None] | None = None) -> list[MandrelLayer]:
    """Cylindrical layers of `shape` about `axis`, `layer` mm thick, zigzag-filled at
    `width` spacing along the region's long axis (or at `angle`, rad, in the unrolled plane).
    `inner` is the mandrel radius (default: the part's smallest distance from the axis)."""
    from freecad_conformal.geometry.cylindrical import CylindricalSlicer

    if not (layer > 0 and width > 0):
        raise PlanError(f"mandrel build: layer {layer!r} and width {width!r} must be > 0 mm")
    start, outer = mandrel_radius(shape, axis)
    start = start if inner is None else float(inner)
    slicer = CylindricalSlicer(shape, axis.point, axis.direction)
    count = int(math.ceil((outer - start) / layer))
    layers: list[MandrelLayer] = []
    for i in range(count):
        radius = start + (i + 0.5) * layer
        section = slicer.section(radius)
        if progress is not None:
            progress(i + 1, count)
        if section.is_empty:
            continue
        nozzle = start + (i + 1) * layer
        pieces = stitch_across_seam(list(_polygons(section.polygons())), 2.0 * math.pi * radius)
        region = as_region(pieces)
        raster = long_axis_angle(region) if angle is None else float(angle)
        try:
            lines = zigzag(region, width, raster, what=f"mandrel layer {i + 1} (r {radius:.3f} mm)")
        except PlanError:
            continue          # a sliver thinner than one bead: nothing to deposit there
        # (s at the section radius, axial) -> (θ, axial): θ is shared by every radius.
        mapped = [np.column_stack((line[:, 0] / radius, line[:, 1])) for line in lines]
        layers.append(MandrelLayer(i, radius, nozzle, raster, mapped))
    if not layers:
        raise PlanError(f"mandrel build: no layer of the part holds a {width:g} mm line "
                        f"between radius {start:.4g} and {outer:.4g} mm")
    return layers


def _polygons(region) -> list[Polygon]:
    return [g for g in getattr(region, "geoms", [region]) if isinstance(g, Polygon) and not g.is_empty]


def _freecad():
    from freecad_conformal.freecad_env import import_freecad
    return import_freecad()


def sample_joint_line(corners: np.ndarray, tolerance: float = DEFAULT_LINEAR_TOLERANCE) -> np.ndarray:
    """A polyline of (θ rad, axial mm, radius mm) corners sampled so each chord stays within
    `tolerance` of the curve the joints trace (a helix piece); corners are kept."""
    corners = np.asarray(corners, dtype=float)
    out = [corners[:1]]
    for k in range(1, len(corners)):
        a, b = corners[k - 1], corners[k]
        radius = max(a[2], b[2], tolerance)
        step = 2.0 * math.acos(max(1.0 - tolerance / radius, -1.0))
        parts = max(int(math.ceil(abs(b[0] - a[0]) / step)), 1)
        s = (np.arange(1, parts + 1) / parts)[:, None]
        out.append(a + s * (b - a))
    return np.concatenate(out)


def rotary_toolpath(layers: list[MandrelLayer], axis: MandrelAxis, flow: float,
                    feed: float = PRINT_FEED, travel_feed: float = TRAVEL_FEED, tool: int = 0,
                    part: str = "part", material: str = "filament",
                    tolerance: float = DEFAULT_LINEAR_TOLERANCE) -> Toolpath:
    """The build for a true rotary axis: every straight line of the unrolled plane (deposit,
    and travel lifted by TRAVEL_LIFT) is a joint_linear segment sampled within `tolerance`
    of its helix, so the post writes one block per straight line."""
    builder = ToolpathBuilder(part=part, material=material, process="rotating mandrel",
                              layers=str(len(layers)))
    previous: tuple[float, float, float] | None = None
    for layer in layers:
        r = layer.nozzle_radius
        for line in layer.lines:
            t0, a0 = float(line[0, 0]), float(line[0, 1])
            travel = [(t0, a0, r + TRAVEL_LIFT), (t0, a0, r)]
            if previous is not None:
                travel = [previous, (previous[0], previous[1], previous[2] + TRAVEL_LIFT)] + travel
            _add(builder, axis, sample_joint_line(np.array(travel), tolerance), kind="travel",
                 feed=travel_feed, tool=tool)
            corners = np.column_stack((line, np.full(len(line), r)))
            _add(builder, axis, sample_joint_line(corners, tolerance), kind="deposit", feed=feed,
                 tool=tool, flow=flow)
            previous = (float(line[-1, 0]), float(line[-1, 1]), r)
    return builder.build()


def _add(builder: ToolpathBuilder, axis: MandrelAxis, samples: np.ndarray, **segment) -> None:
    radial = np.outer(np.cos(samples[:, 0]), axis.u) + np.outer(np.sin(samples[:, 0]), axis.v)
    points = axis.point + np.outer(samples[:, 1], axis.direction) + samples[:, 2:3] * radial
    builder.add_segment(points, radial, interpolation="joint_linear", **segment)


def linear_machine(machine, first_radius: float, layers: list[MandrelLayer]):
    """The controller's view when the rotation is driven as linear axis Y scaled at R0:
    a three-axis machine (same dialect, feeds, X and Z) whose Y mm are R0·θ."""
    from freecad_conformal.post.machine import machine_from_dict

    turns = [abs(float(line[:, 0].max())) + abs(float(line[:, 0].min()))
             for layer in layers for line in layer.lines]
    reach = first_radius * (max(turns, default=0.0) + 2.0 * math.pi) + TRAVEL_LIFT
    axes = {axis.name: {"limits": list(axis.limits), "moves": "tool"} for axis in machine.linear}
    axes["Y"] = {"limits": [-reach, reach], "moves": "table"}
    return machine_from_dict({
        "name": f"{machine.name}, rotation as Y at R0 = {first_radius:.4g} mm",
        "description": "rotary mandrel driven as a linear axis (Cartesian firmware)",
        "dialect": machine.dialect, "linear_axes": axes, "rotary_axes": [],
        "tool_direction": [0, 0, 1], "home": {k: v for k, v in machine.home.items() if k in "XYZ"},
        "rapid_feed": machine.rapid_feed, "max_feed": machine.max_feed,
        "max_rotary_feed": machine.max_rotary_feed, "acceleration": machine.acceleration,
        "light_control": machine.light_control, "filament_diameter": machine.filament_diameter,
    }, source=f"{Path(machine.source).stem}-linear")


def linear_toolpath(layers: list[MandrelLayer], flow: float, feed: float = PRINT_FEED,
                    travel_feed: float = TRAVEL_FEED, tool: int = 0, part: str = "part",
                    material: str = "filament") -> Toolpath:
    """The build for a controller driving the rotation as Y = R0·θ (X axial, Z radius).

    Each deposit move is its own segment so it carries its own compensation: the flow per
    commanded mm is scaled by |(Lx, Ri/R0·Ly)| / |(Lx, Ly)|, which makes the extrusion
    M = K·sqrt((Ri/R0·Ly)² + Lx²), and the feed is corrected the other way so the nozzle
    crosses the surface at `feed`.
    """
    first = layers[0].nozzle_radius
    builder = ToolpathBuilder(part=part, material=material, process="rotating mandrel",
                              mapping=f"rotation as Y at R0 = {first:.6g} mm")
    previous = None
    for layer in layers:
        r = layer.nozzle_radius
        for line in layer.lines:
            xyz = np.column_stack((line[:, 1], first * line[:, 0], np.full(len(line), r)))
            lift = xyz[0] + (0.0, 0.0, TRAVEL_LIFT)
            travel = [lift, xyz[0]] if previous is None else [previous, previous + (0, 0, TRAVEL_LIFT), lift, xyz[0]]
            builder.add_segment(travel, kind="travel", feed=travel_feed, tool=tool)
            steps = np.diff(xyz, axis=0)
            lx, ly = steps[:, 0], steps[:, 1]
            commanded = np.hypot(lx, ly)
            extrusion = compensated_extrusion(lx, ly, r, first, 1.0)
            feeds = corrected_feed(lx, ly, r, first, feed)
            for k in np.flatnonzero(commanded > 0):
                builder.add_segment(xyz[k:k + 2], kind="deposit", feed=float(feeds[k]), tool=tool,
                                    flow=float(flow * extrusion[k] / commanded[k]))
            previous = xyz[-1]
    return builder.build()


@dataclass
class MandrelResult:
    """A planned mandrel build: layers, the toolpath, the G-code and its numbers."""

    layers: list[MandrelLayer]
    mapping: str                  # "rotary" (A axis) or "linear" (rotation as Y at R0)
    first_radius: float
    toolpath: Toolpath
    gcode: str
    blocks: int
    time_s: float
    material_volume: float
    path: Path | None = None

    def report(self) -> str:
        angles = ", ".join(f"{math.degrees(l.angle) % 180.0:.3f}" for l in self.layers[:3])
        return (f"{len(self.layers)} layers from r {self.layers[0].section_radius:.4g} to "
                f"{self.layers[-1].section_radius:.4g} mm ({self.mapping} mapping, R0 "
                f"{self.first_radius:.4g} mm); raster angles {angles}... deg\n"
                f"{self.blocks} G-code blocks, {len(self.gcode.encode()) / 1024:.1f} KB, "
                f"{self.material_volume:.1f} mm3, estimated {self.time_s / 60:.1f} min")


def plan_mandrel(shape, machine, tool, layer: float, out: str | Path | None, *,
                 mapping: str = "rotary", width: float | None = None, feed: float = PRINT_FEED,
                 travel_feed: float = TRAVEL_FEED, angle: float | None = None,
                 material: str = "filament", part: str = "part", toolpath_out: str | Path | None = None,
                 progress: Callable[[int, int], None] | None = None) -> MandrelResult:
    """Plan `shape` on the mandrel of `machine` (name or Machine; its one table rotary axis
    is the mandrel) with `tool` (id or Tool; its diameter is the bead width unless `width`),
    layers `layer` mm thick; write G-code to `out` (atomically, after everything succeeded).

    mapping "rotary": A in degrees through the post-processor; "linear": the rotation as a
    linear Y axis scaled at the first-layer radius R0 with extrusion and feed compensation.
    """
    from freecad_conformal.post.machine import Machine, load_machine
    from freecad_conformal.post.program import post_toolpath
    from freecad_conformal.process.library import ToolLibrary

    machine = machine if isinstance(machine, Machine) else load_machine(machine)
    if isinstance(tool, str):
        tool = ToolLibrary.load().get(tool)
    if mapping not in ("rotary", "linear"):
        raise PlanError(f"mandrel mapping must be 'rotary' or 'linear', got {mapping!r}")
    tables = [a for a in machine.rotary if a.on == "table"]
    if len(machine.rotary) != 1 or not tables:
        raise PlanError(f"machine {machine.name} is not a rotary mandrel: it needs exactly one "
                        f"rotary axis on the table (has {[a.name for a in machine.rotary]})")
    axis = MandrelAxis.make(tables[0].pivot, tables[0].direction)
    bead = float(width if width is not None else tool.diameter)
    layers = mandrel_layers(shape, axis, layer, bead, angle=angle, progress=progress)
    flow = layer * bead
    first = layers[0].nozzle_radius
    if mapping == "rotary":
        toolpath = rotary_toolpath(layers, axis, flow, feed, travel_feed, part=part, material=material)
        target = machine
    else:
        toolpath = linear_toolpath(layers, flow, feed, travel_feed, part=part, material=material)
        target = linear_machine(machine, first, layers)
    result = post_toolpath(toolpath, target)
    summary = toolpath.summary(acceleration=target.acceleration, rapid_feed=target.rapid_feed)
    plan = MandrelResult(layers, mapping, first, toolpath, result.text, len(result.values),
                         result.time_s, summary.material_volume)
    if toolpath_out is not None:
        toolpath.save(toolpath_out)
    if out is not None:
        from freecad_conformal.post.program import write_program
        write_program(out, result)
        plan.path = Path(out)
    return plan
