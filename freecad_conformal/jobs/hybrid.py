"""The hybrid job: deposit with a stock allowance, mill to shape, one program (METHODS 6).

check (tools, machine) → holes to fill (too small to deposit, or across the build) → the
filled part planned as an additive plan (decomposition, layers, 3-D layers) → the sequence
of deposits and milling sessions (paths/hybrid*.py) → one toolpath → G-code → the material
left checked against the part (geometry/stock.py) and the support a planar build would need
(geometry/support.py). Everything is computed before anything is written.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from freecad_conformal.errors import PlanError
from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry.holes import Hole, filled, find_holes
from freecad_conformal.geometry.overhang import DEFAULT_OVERHANG_ANGLE
from freecad_conformal.geometry.rotation import rodrigues_matrix
from freecad_conformal.geometry.stock import OFFSETS, MaterialCheck, check_material
from freecad_conformal.geometry.support import layered_support_volume
from freecad_conformal.jobs.plan import (JobResult, PlanOptions, subpart_summary, check_options,
                                         check_reach, machine_plan)
from freecad_conformal.layers.covering import covering_stack
from freecad_conformal.layers.model import check_thickness
from freecad_conformal.layers.plan import plan_layers
from freecad_conformal.paths.approach import bounding_sphere
from freecad_conformal.paths.ball_finish import finish_faces
from freecad_conformal.paths.assemble import Assembly
from freecad_conformal.paths.hybrid_groups import group_tilted
from freecad_conformal.paths.hybrid_sequence import hybrid_sequence
from freecad_conformal.paths.hybrid_toolpath import DepositProcess, hybrid_toolpath
from freecad_conformal.paths.milling import MillTool
from freecad_conformal.paths.timing import jerk_record, move_seconds
from freecad_conformal.post.program import post_toolpath
from freecad_conformal.settings.plan import SPEED_ROLES
from freecad_conformal.toolpath import KINDS

#: A vertex of the part moved as the plan moved it lies on the plan's sub-parts to this (mm).
SAME_PLACE = 1e-5

#: Support volumes (mm³) this close are a tie: the plan search's choice stands.
SUPPORT_TIE = 1.0

#: Deposition tools get T1; end mills T2, T3, ... in the order given.
DEPOSIT_TOOL_NUMBER = 1


@dataclass
class HybridReport:
    """What milling adds to a plan, for the summary and the JSON report."""

    switches: int
    naive_switches: int
    sessions: list[dict]
    deposit_s: float
    milling_s: float
    travel_s: float
    switch_s: float
    mill_tools: list[str]
    holes_filled: list[str]
    support_planar_mm3: float
    support_hybrid_mm3: float
    check: MaterialCheck | None
    notes: list[str] = field(default_factory=list)
    #: the deposits' volume (each layer's region widened by the stock, as deposited) and
    #: the part's: the mill removes the difference
    deposited_mm3: float = 0.0
    part_mm3: float = 0.0
    #: the motion from the part as modelled to the machine frame: p -> rotation @ p + shift
    rotation: np.ndarray = field(default_factory=lambda: np.eye(3))
    shift: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def frame_back(self) -> list[float]:
        """The motion from the machine frame back to the part as modelled (3x4, row-major)."""
        back = np.eye(4)[:3]
        back[:, :3] = self.rotation.T
        back[:, 3] = -self.rotation.T @ self.shift
        return back.ravel().tolist()

    @property
    def stock_removed_mm3(self) -> float:
        return self.deposited_mm3 - self.part_mm3

    @property
    def support_saved(self) -> float:
        """Fraction of the planar build's support volume this plan does without."""
        if self.support_planar_mm3 <= 0:
            return 0.0
        return 1.0 - self.support_hybrid_mm3 / self.support_planar_mm3

    def to_json(self) -> dict:
        check = None if self.check is None else {
            "deposited_mm3": self.check.deposited, "surface_points": self.check.points,
            "tolerance_mm": OFFSETS[0], "uncut_points": self.check.uncut_points,
            "gouge_points": self.check.gouge_points, "max_uncut_mm": self.check.max_uncut,
            "max_gouge_mm": self.check.max_gouge,
            "uncut_points_outside_corners": self.check.uncut_outside_corners,
            "by_offset_mm": {f"{k:g}": {"uncut_points": v[0], "gouge_points": v[1]}
                             for k, v in self.check.by_offset.items()}}
        return {"switches": self.switches, "naive_switches": self.naive_switches,
                "deposit_time_s": self.deposit_s, "milling_time_s": self.milling_s,
                "travel_time_s": self.travel_s, "switch_time_s": self.switch_s,
                "mill_tools": self.mill_tools, "holes_filled": self.holes_filled,
                "support_planar_mm3": self.support_planar_mm3,
                "support_hybrid_mm3": self.support_hybrid_mm3,
                "support_saved": self.support_saved, "deposited_mm3": self.deposited_mm3,
                "part_mm3": self.part_mm3, "stock_removed_mm3": self.stock_removed_mm3,
                "material_check": check,
                "sessions": self.sessions, "notes": self.notes}


def mill_tools(ids, material: str, library) -> list[MillTool]:
    """The end mills named, with their settings for `material` (T2, T3, ...)."""
    tools = []
    for number, tool_id in enumerate(ids, start=DEPOSIT_TOOL_NUMBER + 1):
        tool = library.get(tool_id)
        if tool.kind != "end_mill":
            raise PlanError(f"mill tool {tool_id!r} is a {tool.kind}; --mill-tool takes end mills")
        settings = tool.settings.get(material)
        if settings is None:
            raise PlanError(f"mill tool {tool_id!r} has no settings for material {material!r} "
                            f"(it has: {', '.join(tool.settings) or 'none'})")
        params = settings.parameters

        def number_of(key: str, default: float, tool_id: str = tool_id) -> float:
            value = params.get(key, default)
            if not isinstance(value, (int, float)) or not value > 0:
                raise PlanError(f"mill tool {tool_id!r}, material {material!r}: parameter "
                                f"{key} = {value!r} must be a number > 0")
            return float(value)

        feed = float(settings.feed) if settings.feed else None
        if feed is None:
            raise PlanError(f"mill tool {tool_id!r}, material {material!r}: no feed_mm_min")
        tools.append(MillTool(
            number=number, id=tool_id, diameter=tool.diameter,
            flute_length=tool.spec.flute_length, holder_diameter=tool.envelope.body_diameter,
            holder_length=tool.envelope.body_length, feed=feed,
            plunge_feed=number_of("plunge_mm_min", feed / 3.0),
            rpm=number_of("spindle_rpm", 10000.0),
            stepover=number_of("stepover_mm", 0.5 * tool.diameter),
            taper_deg=tool.spec.taper_deg, tip_diameter=tool.spec.tip_diameter,
            reach=tool.envelope.tip_length, corner_radius=tool.spec.corner_radius))
    for tool in tools:
        if not (tool.flat or tool.ball or tool.tapered):
            raise PlanError(f"mill tool {tool.id!r}: a corner radius of {tool.corner_radius:g} "
                            f"mm on a {tool.diameter:g} mm cutter; hybrid plans take flat and "
                            "ball end mills and V-bits")
    if tools and not tools[0].flat:
        shape = "tapered" if tools[0].tapered else "not flat"
        raise PlanError(f"mill tool {tools[0].id!r} is {shape}: the first --mill-tool finishes "
                        "walls and faces layers and must be a flat end mill (list a V-bit or "
                        "a ball end mill after it, for corners and curved faces)")
    return tools


def holes_to_fill(solid, root: np.ndarray, limit: float) -> list[Hole]:
    """Holes narrower than `limit` or leaning from the root direction by more than the
    overhang angle (their ceiling would overhang)."""
    return [h for h in find_holes(solid)
            if h.diameter < limit or h.across(root, DEFAULT_OVERHANG_ANGLE)]


def placed_like(reference, plan) -> tuple[np.ndarray, np.ndarray]:
    """(rotation, translation) that moved `reference` (the filled part as given) to where
    the plan's sub-parts stand: one of the placements' quarter turns (`turn_up`), then a
    shift."""
    from freecad_conformal.jobs.placement import turn_up

    shapes = [sub.shape for sub in plan.subparts]
    low = np.min([[s.BoundBox.XMin, s.BoundBox.YMin, s.BoundBox.ZMin] for s in shapes], axis=0)
    points = np.array([tuple(v.Point) for v in reference.Vertexes[:60]])
    App, Part = import_freecad()
    compound = Part.makeCompound(shapes)
    for up in ((0, 0, 1), (0, 0, -1), (1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0)):
        turned, placement = turn_up(reference, up)
        rotation = (rodrigues_matrix(placement.axis, placement.angle) if placement.turned
                    else np.eye(3))
        box = turned.BoundBox
        shift = low - np.array([box.XMin, box.YMin, box.ZMin])
        moved = points @ rotation.T + shift
        if all(compound.distToShape(Part.Vertex(App.Vector(*p)))[0] <= SAME_PLACE for p in moved):
            return rotation, shift
    raise PlanError("the hybrid plan could not follow where the plan placed the part "
                    "(not a quarter turn and a shift): give --root")


def _moved_shape(shape, rotation: np.ndarray, shift: np.ndarray):
    App, _ = import_freecad()
    matrix = App.Matrix(*rotation[0], shift[0], *rotation[1], shift[1], *rotation[2], shift[2],
                        0, 0, 0, 1)
    moved = shape.copy()
    moved.transformShape(matrix)
    return moved


def _moved_hole(hole: Hole, rotation: np.ndarray, shift: np.ndarray) -> Hole:
    return dataclasses.replace(hole, point=rotation @ hole.point + shift,
                               direction=rotation @ hole.direction)


def _additive_plan(solid_filled, options: PlanOptions, root: np.ndarray, checked):
    """(plan, every sub-part's layers, rotation, shift, notes) of the filled part:
    with the root left to "auto" the additive plan search chooses (whole orientations,
    decompositions); a choice that turns the part other than by a quarter turn is not
    followed (the holes and the check need the motion), and the part is then planned as
    modelled (+Z)."""
    from freecad_conformal.jobs.plan import choose_plan

    additive = dataclasses.replace(options, process="additive")
    notes = []
    fixed = dataclasses.replace(additive, root=(float(root[0]), float(root[1]), float(root[2])))
    if isinstance(options.root, str):
        choice = choose_plan(solid_filled, additive, checked)
        try:
            rotation, shift = placed_like(solid_filled, choice.plan)
            check_reach(checked[4], choice.plan)
        except PlanError as exc:
            notes.append(f"the chosen plan ({exc}) is not followed: the part is planned as "
                         "modelled, along +Z")
        else:
            layers = _sliced(choice.plan, options, checked[2], choice.layers)
            if np.allclose(rotation, np.eye(3)):
                return choice.plan, layers, rotation, shift, notes
            return _or_as_modelled(solid_filled, choice.plan, layers, rotation, shift, fixed,
                                   options, checked, notes)
    _, plan = machine_plan(solid_filled, fixed)
    check_reach(checked[4], plan)
    rotation, shift = placed_like(solid_filled, plan)
    return plan, _sliced(plan, options, checked[2]), rotation, shift, notes


def _finishing_hints(check: MaterialCheck, mills: list[MillTool], part, plan,
                     holes: list[Hole]) -> list[str]:
    """What to add to --mill-tool when stock is left that a V-bit or a ball would take."""
    if not check.uncut_points:
        return []
    hints = []
    first = mills[0].id
    in_corners = check.uncut_points - (check.uncut_outside_corners or 0)
    if in_corners > 0 and not any(m.tapered for m in mills):
        hints.append(f"stock is left at {in_corners} points in concave corners the {first} "
                     f"cannot reach: list a V-bit after it (--mill-tool {first},vbit_30deg_6mm) "
                     "to pencil straight ones")
    directions = [np.asarray(sub.build_direction, dtype=float) for sub in plan.ordered()]
    if not any(m.ball for m in mills) and finish_faces(part, directions, holes):
        hints.append(f"curved faces keep the layers' steps under the {first}: list a ball end "
                     f"mill after it (--mill-tool {first},ball_endmill_6mm) to finish them")
    return hints


def _sliced(plan, options: PlanOptions, width: float, known: dict | None = None) -> dict:
    """Every sub-part's layers for beads `width` wide: those the plan search sliced already
    (`known`), the others now."""
    known = known or {}
    settings = options.layers.within_bead(width)
    return {sub.index: known[sub.index] if sub.index in known else plan_layers(sub, settings)
            for sub in plan.ordered()}


def _support(plan, layers: dict) -> float:
    return sum(layered_support_volume(sub.shape, sub.build_direction, layers[sub.index])
               for sub in plan.subparts if layers.get(sub.index))


def _or_as_modelled(solid_filled, plan, layers, rotation, shift, fixed, options, checked,
                    notes):
    """The search's plan, or the part planned as modelled when its layers need less
    support: the search ranks by the overhang of planar builds and does not credit 3-D
    layers, which follow a lean the 45° rule cannot print (a branch leaning 55°: turned a
    quarter by the search, 381 mm³ of support; as modelled with 3-D layers, 75 mm³)."""
    try:
        _, other = machine_plan(solid_filled, fixed)
        check_reach(checked[4], other)
        other_layers = _sliced(other, options, checked[2])
    except PlanError:
        return plan, layers, rotation, shift, notes
    if not any(layer.tilted for stack in other_layers.values() for layer in stack):
        return plan, layers, rotation, shift, notes
    mine, theirs = _support(plan, layers), _support(other, other_layers)
    if theirs >= mine - SUPPORT_TIE:
        return plan, layers, rotation, shift, notes
    notes.append(f"planned as modelled: in its layers (3-D ones one by one) it needs "
                 f"{theirs:.1f} mm³ of support, the plan search's choice {mine:.1f} mm³")
    turn, move = placed_like(solid_filled, other)
    return other, other_layers, turn, move, notes


def plan_hybrid(shape, options: PlanOptions, part: str = "part", library=None,
                progress=None) -> JobResult:
    """The hybrid job (see the module docstring)."""
    from freecad_conformal.geometry.solids import solids_of
    from freecad_conformal.process.library import ToolLibrary

    if options.paths.support.enabled:
        raise PlanError("support (--support / PrintSupport) is printed by additive plans only: "
                        "a hybrid plan reports the support its layers need (and what milling "
                        "saves) but prints none; plan without --support, or --process additive")
    library = library if library is not None else ToolLibrary.load()
    checked = check_options(shape, options, library)
    tool, material_name, width, path_settings, machine = checked
    mills = mill_tools(options.hybrid.mill_tools, material_name, library)
    solids = solids_of(shape, "the part")
    if len(solids) != 1:
        raise PlanError(f"a hybrid plan takes one solid; the part has {len(solids)}")
    solid = solids[0]
    root = np.array([0.0, 0.0, 1.0]) if isinstance(options.root, str) else np.asarray(options.root)
    limit = options.hybrid.fill_holes_below
    limit = 2.0 * width if limit is None else limit
    fill = holes_to_fill(solid, root / np.linalg.norm(root), limit)
    solid_filled = filled(solid, fill)
    plan, layers, rotation, shift, notes = _additive_plan(solid_filled, options, root, checked)
    part_placed = _moved_shape(solid, rotation, shift)
    holes = [_moved_hole(h, rotation, shift) for h in fill]
    for sub in plan.ordered():
        if layers[sub.index]:
            check_thickness(layers[sub.index], options.layers)
            # the mill only removes: deposit all the part holds, sloped tops included
            layers[sub.index] = covering_stack(sub, layers[sub.index], options.layers.workers)
    d_max = options.layers.within_bead(width).bounds[1]
    faces, grouped = {}, []
    for sub in plan.ordered():
        if not any(layer.tilted for layer in layers[sub.index]):
            continue
        stack = group_tilted(sub.shape, layers[sub.index], d_max, mills[0].flute_length,
                             DEFAULT_OVERHANG_ANGLE)
        layers[sub.index], faces[sub.index] = stack.layers, stack.faces
        if stack.replaced[1]:
            grouped.append(f"sub-part {sub.index}: {stack.replaced[0]} 3-D layers deposited as "
                           f"planar layers in {stack.replaced[1]} runs, each faced once")
    notes += grouped
    sequence = hybrid_sequence(plan, layers, path_settings, holes, mills,
                               options.hybrid.stock, d_max, progress, faces, part_placed)
    centre, radius = bounding_sphere([sub.shape for sub in plan.subparts])
    power = None
    if tool.kind == "laser_nozzle":
        material = tool.settings.get(material_name)
        watts = material.power if material is not None and material.power else tool.spec.max_power
        power = min(1.0, watts / tool.spec.max_power)
    process = DepositProcess(DEPOSIT_TOOL_NUMBER, width, path_settings.fill.bead_model,
                             path_settings.feeds, power)
    program = hybrid_toolpath(sequence, process, centre, radius, part=part,
                              material=material_name, tool=tool.id,
                              **jerk_record(options.jerk),
                              process=f"hybrid: deposit {tool.id}, mill "
                                      f"{', '.join(m.id for m in mills)}")
    seconds, segments = move_seconds(program.toolpath, machine.acceleration, options.jerk,
                                     max_feed=machine.max_feed, rapid_feed=machine.rapid_feed)
    kinds = program.toolpath.kind[segments]
    deposit_s = float(seconds[kinds == KINDS.index("deposit")].sum())
    milling_s = float(seconds[kinds == KINDS.index("cut")].sum())
    travel_s = float(seconds.sum()) - deposit_s - milling_s
    switch_s = sequence.switches * machine.process_switch_s
    total_s = float(seconds.sum()) + switch_s
    # The program's header says the time the summary and report say.
    post = post_toolpath(program.toolpath, machine, options.dialect, time_s=total_s)
    check = None
    if options.hybrid.material_check:
        sweeps = [p.sweep for s in sequence.sessions for p in s.passes]
        check = check_material(part_placed, sequence.deposits, sweeps,
                               corner_radius=0.5 * mills[0].diameter)
        notes += _finishing_hints(check, mills, part_placed, plan, holes)
    # the peer: the part as modelled (or turned to the root given), built planar along +Z
    planar = layered_support_volume(solid, root / np.linalg.norm(root))
    # ours: under the layers as deposited (3-D layers turn the overhang away)
    own = _support(plan, layers)
    report = HybridReport(
        switches=sequence.switches, naive_switches=sequence.naive_switches,
        sessions=[{"sub_part": s.subpart, "after_layer": s.last, "from_layer": s.first,
                   "reason": s.reason, "passes": len(s.passes)} for s in sequence.sessions],
        deposit_s=deposit_s, milling_s=milling_s, travel_s=travel_s, switch_s=switch_s,
        mill_tools=[m.id for m in mills],
        holes_filled=[f"{h.diameter:g} mm x {h.length:.2f} mm along "
                      f"{np.round(h.direction, 4).tolist()}" for h in holes],
        support_planar_mm3=planar, support_hybrid_mm3=own, check=check, notes=sequence.notes,
        deposited_mm3=float(sum(prism.volume for prism in sequence.deposits)),
        part_mm3=float(part_placed.Volume),
        rotation=rotation, shift=shift)
    assembly = Assembly(program.toolpath, program.deposits, program.travels, 0, program.cuts)
    summaries = [subpart_summary(sub, layers[sub.index], assembly, width,
                                  path_settings.fill.bead_model)
                 for sub in plan.ordered() if layers[sub.index]]
    plan.notes.extend(notes + sequence.notes)
    return JobResult(part=part, plan=plan, layers=layers, assembly=assembly, post=post,
                     machine=machine, tool_id=tool.id, material_name=material_name,
                     bead_width=width, time_s=total_s,
                     subparts=summaries, settings=dict(options.settings),
                     objective=options.objective, jerk=options.jerk,
                     speeds={role: path_settings.feeds.for_role(role) / 60.0
                             for role in SPEED_ROLES}, hybrid=report)
