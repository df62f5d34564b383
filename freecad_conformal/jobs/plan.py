"""The end-to-end plan: shape -> BuildPlan -> layers -> paths -> toolpath -> G-code + summary.

Everything is computed before anything is written, and every file is written atomically,
so bad input or an impossible plan leaves no output behind.
"""
from __future__ import annotations

import copy
import dataclasses
import io
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from freecad_conformal.errors import KinematicsError, PlanError
from freecad_conformal.fileio import write_all
from freecad_conformal.geometry.frames import vector_text
from freecad_conformal.geometry.shape_cache import ShapeCache
from freecad_conformal.paths import stack_fill
from freecad_conformal.paths.bead import paths_material
from freecad_conformal.paths.assemble import Assembly, PathSettings, assemble
from freecad_conformal.paths.support import SUPPORT_ROLES
from freecad_conformal.paths.timing import DEFAULT_JERK, estimate_time, jerk_record
from freecad_conformal.layers.model import Layer, LayerSettings, check_thickness
from freecad_conformal.layers.plan import plan_layers
from freecad_conformal.decomposition.subparts import (WHOLE_AFTER_FAILURE, WHOLE_ON_MACHINE,
                                                     BuildPlan)
from freecad_conformal.post.branches import choose_rotary
from freecad_conformal.post.kinematics import rotary_candidates
from freecad_conformal.settings.plan import SPEED_ROLES
from freecad_conformal.tolerances import ROUNDING_SLACK, ZERO_LENGTH
from freecad_conformal.post.machine import Machine, load_machine
from freecad_conformal.post.program import PostResult, post_toolpath

#: Tool kinds that deposit material (the others cure or cut).
DEPOSITION_KINDS = ("fdm_nozzle", "laser_nozzle")


@dataclass
class PlanOptions:
    """What the plan command takes: machine, tool (id), material (None: the tool's first),
    layer and path settings (a bead width of None takes the material's width), dialect,
    root direction."""

    machine: str = "trunnion_ac"
    tool: str = "fdm_0p4"
    material: str | None = None
    layers: LayerSettings = field(default_factory=LayerSettings)
    paths: PathSettings = field(default_factory=PathSettings)
    bead_width: float | None = None
    dialect: str | None = None
    jerk: float = DEFAULT_JERK
    #: each solid's root build direction: "auto" (as placed unless turning the solid leaves
    #: less overhang) or a 3-vector (decomposition/decompose.py)
    root: str | tuple[float, float, float] = "auto"
    #: "quick" or "thorough": how many roots an auto root is planned from (decompose.py)
    root_search: str = "quick"
    #: split each solid into support-free sub-parts (False: one sub-part per solid)
    decompose: bool = True
    #: what the choice among candidate plans minimises once residual overhang is least:
    #: "balanced", "time" or "material" (jobs/search.py)
    objective: str = "balanced"
    #: the checked user settings these options were made from (settings/plan.py), for reports
    settings: dict = field(default_factory=dict)
    #: "additive" or "hybrid" (deposition and milling: jobs/hybrid.py)
    process: str = "additive"
    hybrid: "HybridOptions" = field(default_factory=lambda: HybridOptions())


@dataclass
class HybridOptions:
    """Milling in a hybrid plan: the end mills (the first finishes walls and faces 3-D
    layers), the stock allowance (mm), the hole diameter below which holes are filled and
    cut (None: twice the bead width), and whether to check the material left."""

    mill_tools: tuple[str, ...] = ("endmill_6mm",)
    stock: float = 0.5
    fill_holes_below: float | None = None
    material_check: bool = True


@dataclass
class SubPartSummary:
    index: int
    name: str
    direction: np.ndarray
    layers: int
    thickness_min: float
    thickness_max: float
    tilted_layers: int
    deposit_length: float
    material: float
    overhang_area: float


@dataclass
class JobResult:
    """Everything the plan made; `write` puts the files on disk."""

    part: str
    plan: BuildPlan
    layers: dict[int, list[Layer]]
    assembly: Assembly
    post: PostResult
    machine: Machine
    tool_id: str
    material_name: str
    bead_width: float
    time_s: float
    subparts: list[SubPartSummary]
    #: the checked user settings the plan was made with (settings/plan.py keys)
    settings: dict = field(default_factory=dict)
    #: the plans compared, best first, as report rows (jobs/search.Candidate.row); empty
    #: when there was no choice (a root given, several solids, decomposition off)
    candidates: list[dict] = field(default_factory=list)
    #: what the choice among the candidates minimised (PlanOptions.objective)
    objective: str = "balanced"
    #: the speed (mm/s) each role was printed at, derived ones resolved (settings/plan.py)
    speeds: dict = field(default_factory=dict)
    #: the time model's corner speed change (mm/s)
    jerk: float = 0.0
    #: what milling added (jobs/hybrid.HybridReport), None for an additive plan
    hybrid: object = None

    @property
    def material_volume(self) -> float:
        return float(sum(s.material for s in self.subparts))

    @property
    def deposit_length(self) -> float:
        return float(sum(s.deposit_length for s in self.subparts))

    @property
    def support_volume(self) -> float:
        """Material (mm³) of the support printed (`--support`), part of `material_volume`."""
        return paths_material([p for p in self.assembly.paths if p.role in SUPPORT_ROLES],
                              self.bead_width, self.settings.get("bead_model", "rounded"))

    @property
    def travel_length(self) -> float:
        return self.assembly.toolpath.summary().length_by_kind["travel"]

    def summary(self) -> str:
        from freecad_conformal.jobs.report import summary_text

        return summary_text(self)

    def report(self) -> dict:
        from freecad_conformal.jobs.report import report_data

        return report_data(self)

    def write(self, gcode: str | Path, png: str | Path | None = None,
              summary: str | Path | None = None, toolpath: str | Path | None = None,
              report: str | Path | None = None) -> list[Path]:
        """Render everything in memory first, then write the files as one result: all of
        them or, when one cannot be written, none (fileio.write_all)."""
        contents: dict[str | Path, str | bytes] = {gcode: self.post.text}
        if png is not None:
            from freecad_conformal.paths.preview import render_png

            buffer = io.BytesIO()
            count = len(self.subparts)
            process = ", deposit and mill" if self.hybrid is not None else ""
            render_png(self.assembly, buffer,
                       title=f"{self.part}: {count} sub-part{'' if count == 1 else 's'}{process}")
            contents[png] = buffer.getvalue()
        if summary is not None:
            contents[summary] = self.summary()
        if toolpath is not None:
            contents[toolpath] = self.assembly.toolpath.to_bytes()
        if report is not None:
            import json

            contents[report] = json.dumps(self.report(), indent=1) + "\n"
        return write_all(contents)


def resolve_tool(tool_id: str, material: str | None, library=None):
    """(tool, material name, settings) from the tool library; clear errors otherwise."""
    from freecad_conformal.process.library import ToolLibrary

    library = library if library is not None else ToolLibrary.load()
    tool = library.get(tool_id)
    if tool.kind not in DEPOSITION_KINDS:
        raise PlanError(f"tool {tool_id!r} is a {tool.kind}; a deposition plan needs one of "
                        f"{', '.join(DEPOSITION_KINDS)}")
    if material is None:
        material = next(iter(tool.settings), None)
    if material is None:
        return tool, "unspecified", None
    if material not in tool.settings:
        raise PlanError(f"tool {tool_id!r} has no settings for material {material!r} "
                        f"(it has: {', '.join(tool.settings) or 'none'})")
    return tool, material, tool.settings[material]


def check_reach(machine: Machine, plan: BuildPlan) -> None:
    """Every sub-part's build direction must be a tool axis the machine can take, within
    its axis limits."""
    for sub in plan.ordered():
        axis = np.asarray(sub.build_direction, dtype=float).reshape(1, 3)
        axis = axis / np.linalg.norm(axis)
        exc = _unreachable(machine, axis, f"sub-part {sub.index}")
        if exc is not None:
            raise PlanError(f"machine {machine.name!r} cannot point the tool along sub-part "
                            f"{sub.index}'s build direction {np.round(axis[0], 4).tolist()}: {exc}") from exc


def _unreachable(machine: Machine, axis: np.ndarray, where: str) -> KinematicsError | None:
    """Why the machine cannot take the unit tool `axis` (1, 3) of the part on its table
    (None: it can), from its home joints."""
    locate = lambda _i: where  # noqa: E731
    try:
        choose_rotary(machine, rotary_candidates(machine, axis, locate),
                      machine.home_joints()[3:], locate)
    except KinematicsError as exc:
        return exc
    return None


def machine_tilts(machine: Machine) -> bool:
    """Whether the machine can point the tool along some direction of the part on its table
    other than +Z (one of the cube's 26). A plain 3-axis printer cannot: each sub-part of a
    decomposition would need a direction of its own, so none can be built, and trying the
    part's six placements for one cost CrankArm 18 s before it was built whole anyway."""
    from freecad_conformal.geometry.overhang import CUBE_DIRECTIONS

    return any(_unreachable(machine, d.reshape(1, 3), "a direction") is None
               for d in CUBE_DIRECTIONS if d[2] < 1.0)


#: Tilts from +Z, and turns about it, probed by `reach_by_tilt` (rad).
PROBE_TILTS = np.radians(np.arange(0.0, 181.0, 15.0))
PROBE_TURNS = np.radians(np.arange(0.0, 360.0, 30.0))


def reach_by_tilt(machine: Machine) -> bool:
    """Whether the machine reaches a tool direction of the part on its table according to
    its angle from +Z alone, whatever way it leans (a freely turning table C: the trunnion,
    the head machine; a 3-axis printer): a plan laid out the same way up then passes or
    fails the reach check however the part was turned about the vertical to make it."""
    for tilt in PROBE_TILTS:
        reached = {_unreachable(machine, np.array([[np.sin(tilt) * np.cos(turn),
                                                    np.sin(tilt) * np.sin(turn),
                                                    np.cos(tilt)]]), "a direction") is None
                   for turn in PROBE_TURNS}
        if len(reached) > 1:
            return False
    return True


def buildable_layers(settings: LayerSettings, machine: Machine, width: float) -> LayerSettings:
    """`settings` as the machine can build them with beads `width` wide: planar layers only
    where it cannot tilt the tool, as 3-D layers tilt it (the pipe elbow's bend on the
    3-axis printer: its post refused the first tilted layer after 19 s of planning), and
    none taller than the bead is wide (`LayerSettings.within_bead`)."""
    settings = settings.within_bead(width)
    if settings.tilt and not machine_tilts(machine):
        return dataclasses.replace(settings, tilt=False)
    return settings


def check_platform(machine: Machine) -> None:
    """Refuse a machine with nothing to build a part on at Z = 0 (a rotary mandrel): set down
    over the mandrel's axis, the part would be laid out, sliced and posted before its first
    move left the travel."""
    if not machine.platform:
        raise PlanError(f"machine {machine.name!r} ({machine.source}) has no build platform: "
                        "its parts grow on the mandrel. Plan them with `plan --mandrel` or the "
                        "`mandrel` command, or choose a machine with a platform")


def check_fits(shape, machine: Machine) -> None:
    """Refuse, before any geometry work, a part that fits the machine's travel in no
    orientation: turned any way, its extent along some axis is at least its largest box
    dimension / √3 (the part's diameter is at least that box dimension)."""
    box = shape.BoundBox
    largest = max(box.XLength, box.YLength, box.ZLength)
    reach = max(high - low for low, high in (axis.limits for axis in machine.linear))
    if largest / math.sqrt(3.0) > reach:
        raise PlanError(f"the part ({box.XLength:.1f} x {box.YLength:.1f} x {box.ZLength:.1f} mm) "
                        f"cannot fit {machine.name} in any orientation: its longest travel is "
                        f"{reach:.1f} mm")


def _platform_centre(machine: Machine) -> np.ndarray:
    """Where a part goes on the platform: over the table's rotary pivot, else the middle of
    the X and Y travel."""
    for axis in machine.table_axes:
        return np.array([axis.pivot[0], axis.pivot[1]], dtype=float)
    limits = {axis.name: axis.limits for axis in machine.linear}
    return np.array([0.5 * sum(limits.get(name, (0.0, 0.0))) for name in ("X", "Y")])


#: The centred copies made of each part, by shape identity and machine travel: each
#: candidate plan of a part is placed again, and one copy shares its faces' meshes and
#: measures across them (`placement.turn_up` keeps one turned copy of it in turn).
_CENTRED: ShapeCache[dict] = ShapeCache(limit=32, oriented=True)


def centred_if_off_platform(shape, machine: Machine):
    """(shape, note): a part that could leave the machine's X/Y travel once turned to be
    built (its bounding sphere, about which the layout turns it, reaches outside) is moved
    over the platform's centre (a note says by how much); any other part is left as placed.
    The Pump_Nut, modelled at y 263..278 and 60 mm tall, reached y = 300.3 on its side.
    The same part on the same travel gets the same copy."""
    travel = (tuple((axis.name, tuple(axis.limits)) for axis in machine.linear),
              tuple(_platform_centre(machine)))
    return _CENTRED.get_keyed((shape,), travel, lambda: _centred(shape, machine))


def _centred(shape, machine: Machine):
    limits = {axis.name: axis.limits for axis in machine.linear}
    box = shape.BoundBox
    radius = 0.5 * box.DiagonalLength
    inside = all(name not in limits or (limits[name][0] <= centre - radius
                                        and centre + radius <= limits[name][1])
                 for name, centre in (("X", box.Center.x), ("Y", box.Center.y)))
    if inside:
        return shape, None
    centre = _platform_centre(machine)
    shift = (float(centre[0] - box.Center.x), float(centre[1] - box.Center.y), 0.0)
    if math.hypot(shift[0], shift[1]) <= ZERO_LENGTH:
        return shape, None     # centred already (a copy this made, planned again)
    from freecad_conformal.freecad_env import import_freecad
    from freecad_conformal.geometry.solids import moved_rigidly

    App, _ = import_freecad()
    moved = shape.copy(True, True)
    moved.translate(App.Vector(*shift))
    moved_rigidly(shape, moved)
    return moved, (f"part modelled where, turned to be built, it could leave the machine's X/Y "
                   f"travel: moved by ({shift[0]:+.3f}, {shift[1]:+.3f}, +0.000) mm over the "
                   "platform's centre; its G-code is in that frame")


def _part_size(shape) -> float:
    box = shape.BoundBox
    return float(min(box.XLength, box.YLength, box.ZLength))


def _settings(options: PlanOptions, tool, material) -> tuple[float, PathSettings]:
    paths = copy.deepcopy(options.paths)
    width = options.bead_width
    if width is None:
        width = material.width if material is not None and material.width else tool.diameter
    paths.fill.bead_width = width
    built_in = PathSettings().feeds

    def derived(role: str) -> bool:
        # From settings: the user gave no speed; from Python: the feed is the built-in one.
        if options.settings:
            return options.settings.get(f"{role}_speed") is None
        return getattr(options.paths.feeds, role) == getattr(built_in, role)

    if material is not None and material.feed:
        for role in ("perimeter", "external_perimeter"):
            if derived(role):
                setattr(paths.feeds, role, float(material.feed))
    travel = material.parameters.get("travel_mm_min") if material is not None else None
    if isinstance(travel, (int, float)) and derived("travel"):
        paths.feeds.travel = float(travel)
    return float(width), paths


def check_options(shape, options: PlanOptions, library=None, part: str | None = None):
    """Validate everything that does not need the decomposition (run it first: it is quick).
    `part`: the part's name, for the messages (a file's stem on the command line).

    Returns (tool, material name, bead width, path settings, machine).
    """
    from freecad_conformal.geometry.solids import solids_of

    # A face, an edge or a vertex is not a part; the message names the file it came from.
    solids_of(shape, f"the part {part!r}" if part else "the part")
    size = _part_size(shape)
    machine = load_machine(options.machine)
    check_platform(machine)
    check_fits(shape, machine)
    options.layers.validate(part_size=size)
    tool, material_name, material = resolve_tool(options.tool, options.material, library)
    width, path_settings = _settings(options, tool, material)
    path_settings.fill.validate()
    path_settings.feeds.validate()
    if width > size:
        raise PlanError(f"bead width {width:g} mm is larger than the part ({size:.3f} mm)")
    check_layers_fit_bead(options.layers, width, options.tool)
    return tool, material_name, width, path_settings, machine


def check_layers_fit_bead(layers: LayerSettings, width: float, tool: str) -> None:
    """Refuse layers taller than the bead is wide: no nozzle lays such a bead (PrusaSlicer
    refuses a layer height above the nozzle diameter), and the bead models cap it at a
    circle's worth, so a 5 mm layer of 0.4 mm beads was planned as a sparse tenth of the
    part without a word. The bounds of adaptive and 3-D layers are checked where the
    user set them; a maximum left to its default is taken down to the bead width
    (`buildable_layers`)."""
    given = [("layer height (--layer-height / LayerHeight)", layers.thickness)]
    if layers.max_thickness is not None:
        given.append(("maximum layer height (--layer-max / LayerMax)", layers.max_thickness))
    if layers.min_thickness is not None:
        given.append(("minimum layer height (--layer-min / LayerMin)", layers.min_thickness))
    for name, value in given:
        if value > width * (1.0 + ROUNDING_SLACK):
            raise PlanError(f"{name} {value:g} mm is taller than the bead is wide ({width:g} mm, "
                            f"tool {tool}): a bead cannot be taller than it is wide; use at "
                            f"most {width:g} mm, or a wider bead (--bead-width / BeadWidth)")


@dataclass
class Choice:
    """The plan chosen for a part: where it sits, its plan, the layers the choice already
    sliced (None: not yet), and every candidate compared, best first (jobs/search.py)."""

    placed: object
    plan: BuildPlan
    layers: dict[int, list[Layer]] | None = None
    candidates: list = field(default_factory=list)


def choose_plan(shape, options: PlanOptions, checked, decompose=None,
                progress=None) -> Choice:
    """The plan the job builds (run `check_options` first: `checked` is its result). With
    the root left to "auto", decomposition on and one solid, the candidates of
    `jobs/search.py` (support-free whole orientations, else the decomposition) are laid out,
    sliced and costed, and the least residual overhang, then the cheapest by
    `options.objective`, wins; otherwise the one plan of `machine_plan`, or each solid built
    whole when no decomposition can be built. `progress(text)` hears of each candidate."""
    from freecad_conformal.geometry.section_pool import warm_workers
    from freecad_conformal.geometry.solids import cavities_note, solids_of, united_overlaps

    tool, _, _, path_settings, machine = checked
    shape, fused = united_overlaps(shape)
    # Centred first, so that what the search measures of the part (its meshes, its overhang
    # in each direction) is measured of the very shape every plan places (Pump_Nut, modelled
    # off the platform, was meshed and scanned twice: 0.2 s of its 0.8 s choice).
    shape, centred = centred_if_off_platform(shape, machine)
    solids = solids_of(shape)
    first_notes = [note for note in (fused, centred, cavities_note(solids)) if note]
    warm_workers(shape, options.layers.thickness)
    flat = options.decompose and not machine_tilts(machine)
    searched = options.decompose and isinstance(options.root, str)
    if searched and len(solids) > 1:
        found = _each_solid_searched(shape, solids, options, checked, flat, decompose,
                                     progress)
        if found is not None:
            found.plan.notes[:0] = first_notes
            return found
    if not (searched and len(solids) == 1):
        split = options.decompose and not flat
        try:
            placed, plan = machine_plan(shape, options, decompose, split=split, tool=tool,
                                        machine=machine, whole_best=flat)
        except PlanError as exc:
            if not split:
                raise
            # No decomposition can be built (no collision-free order): each solid whole is
            # what a user can still print.
            placed, plan = machine_plan(shape, options, decompose, split=False, tool=tool,
                                        machine=machine)
            plan.notes.insert(0, f"no decomposition could be built ({exc}); each solid is "
                                 "built whole")
            plan.support_reason = WHOLE_AFTER_FAILURE
        if flat:
            _built_whole_on(machine, plan)
        plan.notes[:0] = first_notes
        return Choice(placed, plan)
    from freecad_conformal.geometry.overhang import DEFAULT_OVERHANG_ANGLE
    from freecad_conformal.jobs.search import builds, plan_candidates, ranked
    from freecad_conformal.paths.cost import Motion

    early = None if flat else _early_trial(solids[0])

    def make_plan(root, split: bool):
        return machine_plan(shape, dataclasses.replace(options, root=root, decompose=split),
                            decompose, tool=tool, machine=machine, early=early)

    def child_request() -> dict:
        from freecad_conformal.jobs.coarse_child import coarse_request

        return coarse_request(shape, options, tool, machine)

    # A child lays out and costs orientations as make_plan does only with the decomposition
    # it would import itself (a caller's own cannot cross).
    try:
        candidates = ranked(plan_candidates(solids[0], make_plan,
                                            buildable_layers(options.layers, machine,
                                                             path_settings.fill.bead_width),
                                            path_settings,
                                            Motion.of(machine, options.jerk),
                                            DEFAULT_OVERHANG_ANGLE, progress, options.objective,
                                            child_request if decompose is None else None,
                                            early, split=not flat),
                            options.objective)
    finally:
        if early is not None:
            early.stop()
    best = candidates[0]
    if flat:
        _built_whole_on(machine, best.plan)
    best.plan.notes[:0] = first_notes
    if builds(candidates) > 1:
        best.plan.notes.append(f"{best.label}: chosen among {builds(candidates)} candidate "
                               f"plans (least residual overhang, then cheapest: "
                               f"{options.objective})")
    return Choice(best.placed, best.plan, best.layers, candidates)


def _built_whole_on(machine: Machine, plan: BuildPlan) -> None:
    """Say that `plan` builds each solid whole because `machine` cannot tilt the tool."""
    plan.notes.insert(0, f"machine {machine.name!r} cannot tilt the tool off +Z: no "
                         "decomposition (each sub-part is built along a direction of its "
                         "own); each solid is built whole, in planar layers")
    plan.support_reason = WHOLE_ON_MACHINE


def _each_solid_searched(shape, solids: list, options: PlanOptions, checked, flat: bool,
                         decompose=None, progress=None) -> Choice | None:
    """The plan of a part of several solids, each solid that builds support-free whole in
    some direction (any, on a machine that cannot tilt) built along the winner of its own
    search (`jobs/search.py`, the solid alone on the platform, as a one-solid part is
    searched), the others decomposed as before. Two plates modelled standing stood on their
    edges, 400 layers and 70 min, where one alone is laid flat (15 layers, 18 min). None
    when no solid builds whole, or one that should has no whole build alone: the part is
    then decomposed solid by solid (`machine_plan`)."""
    from freecad_conformal.geometry.overhang import DEFAULT_OVERHANG_ANGLE
    from freecad_conformal.jobs.search import builds, builds_whole, plan_candidates, ranked
    from freecad_conformal.paths.cost import Motion

    whole = [flat or builds_whole(solid, DEFAULT_OVERHANG_ANGLE) for solid in solids]
    if not any(whole):
        return None
    tool, _, width, path_settings, machine = checked
    layer_settings = buildable_layers(options.layers, machine, width)
    motion = Motion.of(machine, options.jerk)
    directions: dict[int, tuple[float, float, float]] = {}
    notes: list[str] = []
    for number, solid in enumerate(solids, start=1):
        if not whole[number - 1]:
            continue

        def make_plan(root, split: bool, solid=solid):
            return machine_plan(solid, dataclasses.replace(options, root=root, decompose=split),
                                tool=tool, machine=machine)

        def told(text: str, number=number) -> None:
            if progress is not None:
                progress(f"solid {number}: {text}")

        try:
            candidates = ranked(plan_candidates(solid, make_plan, layer_settings, path_settings,
                                                motion, DEFAULT_OVERHANG_ANGLE, told,
                                                options.objective, split=False),
                                options.objective)
        except PlanError:
            return None      # no whole build of this solid alone: plan the part as before
        best = candidates[0]
        directions[number - 1] = best.direction
        if builds(candidates) > 1:
            notes.append(f"solid {number}: {best.label} chosen among {builds(candidates)} "
                         f"candidate plans (least residual overhang, then cheapest: "
                         f"{options.objective})")
    if all(whole):
        placed, plan = machine_plan(shape, options, split=False, tool=tool, machine=machine,
                                    directions=[directions[k] for k in range(len(solids))])
    else:
        # The others need a decomposition: each is decomposed as before, these built whole.
        placed, plan = machine_plan(shape, options, decompose, split=True, tool=tool,
                                    machine=machine, whole_along=directions)
    if flat:
        _built_whole_on(machine, plan)
    plan.notes.extend(notes)
    return Choice(placed, plan)


def _early_trial(solid):
    """The solid's decomposition trial begun now (`decomposition/trial.EarlyTrial`), where
    the decomposition would start one: a free-form solid (`worth_a_trial`). The child reads
    and meshes it while the search scans whole orientations first."""
    from freecad_conformal.decomposition.trial import EarlyTrial, worth_a_trial

    return EarlyTrial(solid) if worth_a_trial(solid) else None


def plan_additive(shape, options: PlanOptions, part: str = "part", library=None,
                  progress=None) -> JobResult:
    """The whole job as `plan` and the Job object make it: the options checked first (before
    any geometry work), then the plan chosen and placed on the machine (`choose_plan`), then
    layers, paths and G-code."""
    checked = check_options(shape, options, library, part)
    # The fills' child starts while the plan is chosen, to be ready for its paths.
    stack_fill.prestart()
    try:
        choice = choose_plan(shape, options, checked)
        if (choice.plan.support_area > 0 and options.decompose and options.root == "auto"
                and options.root_search == "quick" and len(choice.plan.subparts) > 1):
            choice.plan.notes.append(
                "a thorough root search (--root-search thorough; Root search in the GUI) "
                "also plans each solid turned over, which may leave less overhang")
        return run_job(choice.placed, choice.plan, options, part, library, progress,
                       checked=checked, layers=choice.layers, candidates=choice.candidates)
    finally:
        stack_fill.drop_prestarted()


def run_job(shape, plan: BuildPlan, options: PlanOptions, part: str = "part",
            library=None, progress=None, checked=None, layers=None,
            candidates=()) -> JobResult:
    """Plan layers (unless `layers` are given, as `choose_plan` sliced them) and paths for
    every sub-part, build the toolpath and post it.

    Raises ConformalError subclasses (PlanError, ProcessError, KinematicsError, PostError)
    with messages that name the parameter or sub-part at fault.
    """
    from freecad_conformal.jobs.search import twin_labels

    if checked is None:
        checked = check_options(shape, options, library)
    tool, material_name, width, path_settings, machine = checked
    check_reach(machine, plan)
    sliced = layers or {}
    layers = {}
    notes: list[str] = []
    layer_settings = buildable_layers(options.layers, machine, width)
    for sub in plan.ordered():
        layers[sub.index] = (sliced[sub.index] if sub.index in sliced
                             else plan_layers(sub, layer_settings))
        if not layers[sub.index]:
            notes.append(f"sub-part {sub.index} is thinner than the thinnest layer "
                         f"({options.layers.bounds[0]:g} mm): its {sub.volume:.1f} mm3 are not built")
        check_thickness(layers[sub.index], options.layers)
        if progress is not None:
            progress(sub.index)
    assembly = assemble(plan, layers, path_settings, tool.envelope,
                        motion=(machine.acceleration, options.jerk), part=part,
                        material=material_name, tool=tool.id,
                        **jerk_record(options.jerk))
    notes.extend(f"sub-parts {', '.join(map(str, run))} laid in turn, a layer of each per "
                 "round: each cools while the others are built, instead of slowing down"
                 for run in assembly.alternated)
    notes.extend(assembly.support_notes)
    seconds = estimate_time(assembly.toolpath, machine.acceleration, options.jerk,
                            max_feed=machine.max_feed, rapid_feed=machine.rapid_feed)
    # The program's header says the time the summary and report say.
    post = post_toolpath(assembly.toolpath, machine, options.dialect, time_s=seconds)
    summaries = [subpart_summary(sub, layers[sub.index], assembly, width, path_settings.fill.bead_model)
                 for sub in plan.ordered()
                 if layers[sub.index]]
    plan.notes.extend(notes)
    # A chosen plan whose cost the choice never read (compared with none, or the one exact
    # candidate of least overhang) reports its own time and material, as do its twins.
    chosen_cost = next((c.cost for c in candidates if c.plan is plan), None)
    figures = (seconds, float(sum(s.material for s in summaries)))
    rows = [c.row(chosen=c.plan is plan,
                  figures=figures if c.cost is chosen_cost and not c.costed else None,
                  same_build_as=twin)
            for c, twin in zip(candidates, twin_labels(candidates))]
    return JobResult(part=part, plan=plan, layers=layers, assembly=assembly, post=post,
                     machine=machine, tool_id=tool.id, material_name=material_name,
                     bead_width=width, time_s=seconds, subparts=summaries,
                     settings=dict(options.settings), candidates=rows,
                     objective=options.objective, jerk=options.jerk,
                     speeds={role: path_settings.feeds.for_role(role) / 60.0
                             for role in SPEED_ROLES})


def subpart_summary(sub, layers: list[Layer], assembly: Assembly, width: float,
                     bead_model: str) -> SubPartSummary:
    mine = [p for p in assembly.paths if p.subpart == sub.index]
    length = float(sum(p.length for p in mine))
    material = paths_material(mine, width, bead_model)
    return SubPartSummary(
        index=sub.index, name=sub.name or f"sub-part {sub.index}",
        direction=np.asarray(sub.build_direction, dtype=float), layers=len(layers),
        thickness_min=min(layer.thickness_min for layer in layers),
        thickness_max=max(layer.thickness_max for layer in layers),
        tilted_layers=sum(layer.tilted for layer in layers), deposit_length=length,
        material=material, overhang_area=float(sub.overhang_area))


#: Least gap (mm) between solids laid out side by side on the platform; the tool's body
#: diameter when wider, so the body fits between them (decomposition/layout.py).
MIN_LAYOUT_GAP = 5.0


def machine_plan(shape, options: PlanOptions, decompose=None, split: bool | None = None, *,
                 tool=None, machine: Machine | None = None, early=None,
                 whole_best: bool = False, directions=None, whole_along=None):
    """(placed shape, BuildPlan) as the machine builds the part: decomposed with each
    solid's root along `options.root` ("auto": as placed unless turning the solid leaves
    less overhang), each solid standing on the platform (`decomposition/layout.py`), and the
    whole part turned on the table when the machine cannot reach one of the sub-parts
    (`jobs/placement.py`; the plan notes every move, and a root given as a direction turns
    with the part). `split=False` builds each solid in one piece along the root (+Z when
    "auto") instead of decomposing it (default: `options.decompose`). `tool` and `machine`
    are those `check_options` resolved (default: read again from the options; the search
    plans each candidate with the ones it checked: reading the tool library took 13 ms of
    the wedge's 0.14 s choice). `early`: a solid's trial the search began
    (`decomposition/trial.EarlyTrial`), passed on to the decomposition. `whole_best`: built
    whole with the root left to "auto", each solid stands along its own direction of least
    overhang (a machine that cannot tilt the tool: a planar slicer's best orientation).
    `directions`: built whole (`split` False), each solid along its own direction (part
    frame, one per solid in `solids_of` order), turned with the part. `whole_along`:
    decomposed, but the solids it maps (index: part-frame direction) built whole so."""
    from freecad_conformal.decomposition.build_order import BlockedOrder, build_order
    from freecad_conformal.decomposition.layout import lay_out
    from freecad_conformal.jobs.placement import reachable_plan

    if decompose is None:
        from freecad_conformal.decomposition.decompose import decompose
    if split is None:
        split = options.decompose
    if tool is None:
        tool, _, _ = resolve_tool(options.tool, options.material)
    gap = max(MIN_LAYOUT_GAP, tool.envelope.body_diameter)
    if machine is None:
        machine = load_machine(options.machine)

    def laid_out(placed, placement, check_collisions: bool):
        # Side by side on one platform, each solid's tool meets what is built of the others:
        # the order of several solids is searched once, after they are laid out.
        root = options.root
        if not isinstance(root, str):
            root = tuple(float(c) for c in placement.rotate(root))
        if split:
            # The job builds the plan; it shows no centroidal axis (the Analysis does).
            begun = {} if early is None else {"early": early}
            # A part of several solids is not searched (`choose_plan`): a solid of it that
            # is support-free whole is built whole, as the search builds one solid.
            plan = decompose(placed, tool=tool, root_direction=root,
                             check_collisions=check_collisions, with_axes=False,
                             thorough=options.root_search == "thorough",
                             whole_when_support_free=len(placed.Solids) > 1,
                             whole_along=None if whole_along is None else {
                                 k: tuple(float(c) for c in placement.rotate(d))
                                 for k, d in whole_along.items()}, **begun)
        elif directions is not None:
            plan = single_plan(placed, [tuple(float(c) for c in placement.rotate(d))
                                        for d in directions])
        elif not isinstance(root, str):
            plan = single_plan(placed, root)
        else:
            plan = single_plan(placed, BEST_DIRECTION if whole_best else (0.0, 0.0, 1.0))
        laid = lay_out(plan, gap)
        if len(placed.Solids) > 1:
            laid.order = build_order(laid.subparts, tool=tool, notes=laid.notes,
                                     one_platform=True)
        return laid

    def planned(placed, placement):
        several = len(placed.Solids) > 1
        try:
            return laid_out(placed, placement, check_collisions=not several)
        except BlockedOrder:
            if not (split and several):
                raise
            # Each solid's own order was left to the search over all of them; blocked within
            # one, that solid's own check mends it (fusing a blocked sub-part back into its
            # parent), and the others keep their decomposition.
            return laid_out(placed, placement, check_collisions=True)

    def turning_helps() -> bool:
        # A root given is turned with the part and every plan is laid out root up, so the
        # placements give one plan, whose reach depends on its tilts alone on most machines
        # (CrankArm with --root 0,0,-1 was decomposed six times, 25 s, to fail each time).
        return isinstance(options.root, str) or not split or not reach_by_tilt(machine)

    shape, centred = centred_if_off_platform(shape, machine)
    placed, plan, _ = reachable_plan(shape, planned, lambda p: check_reach(machine, p),
                                     turning_helps)
    plan = _within_travel(plan, machine)
    if centred:
        plan.notes.insert(0, centred)
    return placed, plan


def _within_travel(plan: BuildPlan, machine: Machine) -> BuildPlan:
    """The laid-out plan moved over the platform's centre when its solids, set side by side,
    reach outside the machine's X/Y travel (CrankArm's arm went to x = 355, past 300), or
    when building a sub-part along its direction would drive an axis past its travel
    (`_travel_reached`)."""
    from freecad_conformal.decomposition.layout import shifted

    limits = {axis.name: axis.limits for axis in machine.linear}
    boxes = [sub.shape.BoundBox for sub in plan.subparts]
    low = np.array([min(b.XMin for b in boxes), min(b.YMin for b in boxes)])
    high = np.array([max(b.XMax for b in boxes), max(b.YMax for b in boxes)])
    inside = all(name not in limits or (limits[name][0] <= low[k] and high[k] <= limits[name][1])
                 for k, name in enumerate(("X", "Y")))
    if inside and _travel_reached(plan, machine):
        return plan
    why = ("its solids, set side by side, reached outside the machine's X/Y travel" if not inside
           else "building it where it was laid out drove an axis past the machine's travel")
    offset = _platform_centre(machine) - 0.5 * (low + high)
    moved = plan if np.linalg.norm(offset) <= ZERO_LENGTH else shifted(plan, offset, why)
    moved = _turned_to_fit(moved, machine)
    _refuse_beyond_travel(moved, machine)
    return moved


#: Turns (degrees) about the vertical tried, smallest first, for a plan whose footprint is
#: wider than the X/Y travel: a 650 mm bar fits the trunnion's 600 x 600 mm turned by 27°.
FIT_TURNS = tuple(range(1, 180))


def _turned_to_fit(plan: BuildPlan, machine: Machine) -> BuildPlan:
    """The plan, laid out over the platform's centre, turned about the vertical by the least
    of FIT_TURNS that brings its footprint inside the X/Y travel, when it is wider than the
    travel as laid out and every sub-part is built straight up (a turn about the vertical
    then changes nothing but where it stands); otherwise the plan as it is. The footprint is
    read from each sub-part's vertices and box corners (it may only be overstated)."""
    from freecad_conformal.decomposition.layout import turned_about_vertical
    from freecad_conformal.geometry.shape_parts import vertex_points

    limits = {axis.name: axis.limits for axis in machine.linear}
    if "X" not in limits or "Y" not in limits:
        return plan
    if not all(np.allclose(sub.build_direction, (0.0, 0.0, 1.0), atol=ZERO_LENGTH)
               for sub in plan.subparts):
        return plan
    widths = np.array([limits["X"][1] - limits["X"][0], limits["Y"][1] - limits["Y"][0]])
    points = []
    for sub in plan.subparts:
        box = sub.shape.BoundBox
        points += [p[:2] for p in vertex_points(sub.shape)]
        points += [np.array([x, y]) for x in (box.XMin, box.XMax) for y in (box.YMin, box.YMax)]
    points = np.array(points)
    low, high = points.min(axis=0), points.max(axis=0)
    if np.all(high - low <= widths):
        return plan
    pivot = 0.5 * (low + high)
    for degrees in FIT_TURNS:
        angle = math.radians(degrees)
        turn = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
        turned = (points - pivot) @ turn.T + pivot
        t_low, t_high = turned.min(axis=0), turned.max(axis=0)
        if np.all(t_high - t_low <= widths):
            shift = _platform_centre(machine) - 0.5 * (t_low + t_high)
            return turned_about_vertical(plan, angle, pivot, shift,
                                         "set straight it was wider than the machine's X/Y "
                                         "travel")
    return plan


#: How far (mm) inside a sub-part's vertices its deposits surely reach: the external loop runs
#: half a bead inside the faces, and at a corner as sharp as 12° a 0.4 mm bead's loop still
#: passes within 2 mm of the vertex. A vertex moved this far towards the sub-part's centre
#: that the machine cannot reach means its paths cannot be posted either.
DEPOSIT_REACH = 2.0


def _refuse_beyond_travel(plan: BuildPlan, machine: Machine) -> None:
    """Refuse a plan, laid out over the platform's centre, that the machine cannot build
    there: a point its paths surely reach is out of the travel (checked as the post checks
    it, `post.kinematics.inverse`). A 900 mm bar on the trunnion's 600 mm of X travel was
    sliced, filled and posted for 13 s before the post refused its first point."""
    from freecad_conformal.errors import BeyondTravelError
    from freecad_conformal.geometry.shape_parts import vertex_points

    for sub in plan.subparts:
        points = np.array(vertex_points(sub.shape))
        if not len(points):
            continue
        inward = np.array(tuple(sub.shape.CenterOfMass)) - points
        distance = np.linalg.norm(inward, axis=1)
        step = np.minimum(1.0, DEPOSIT_REACH / np.maximum(distance, DEPOSIT_REACH))
        axis, error = _out_of_reach(machine, points + inward * step[:, None], sub)
        if error is not None:
            span = points.max(axis=0) - points.min(axis=0)
            raise BeyondTravelError(
                machine.name, f"{sub.name}, {span[0]:.1f} x {span[1]:.1f} x {span[2]:.1f} mm as "
                f"laid out over the platform's centre to be built along {vector_text(axis)}, "
                f"would leave it: {error}") from error


def _out_of_reach(machine: Machine, points: np.ndarray, sub) -> tuple[np.ndarray, object]:
    """(the sub-part's unit build direction, the KinematicsError the post would raise for
    the tool there at `points`, or None when it reaches them all)."""
    from freecad_conformal.post.kinematics import inverse

    axis = np.asarray(sub.build_direction, dtype=float)
    axis = axis / np.linalg.norm(axis)
    try:
        inverse(machine, points, np.repeat(axis.reshape(1, 3), len(points), axis=0))
    except KinematicsError as exc:
        return axis, exc
    return axis, None


def _travel_reached(plan: BuildPlan, machine: Machine) -> bool:
    """Whether the machine reaches, inside its linear travel, every vertex of every
    sub-part with the tool along the sub-part's build direction, and the point the tool
    retracts to from there (onto the safe sphere of `paths/approach.py`). A tilted head
    swings the axes by its own length and a turned table swings the part about its pivot:
    CrankArm's arrangement, set beside its pin at x 50..76 within the head machine's
    +-150 mm, had a retract from its sideways ribs need Y = 150.6 mm, and the post refused
    it after 23 s of layers and paths; moved over the table's pivot it is built."""
    from freecad_conformal.geometry.shape_parts import vertex_points
    from freecad_conformal.paths.approach import SAFE_MARGIN, bounding_sphere, exit_distance

    centre, radius = bounding_sphere([sub.shape for sub in plan.subparts])
    for sub in plan.subparts:
        points = np.array(vertex_points(sub.shape))
        if not len(points):
            continue
        axis = np.asarray(sub.build_direction, dtype=float)
        axis = axis / np.linalg.norm(axis)
        lifted = np.array([p + exit_distance(p, axis, centre, radius + SAFE_MARGIN) * axis
                           for p in points])
        if _out_of_reach(machine, np.vstack((points, lifted)), sub)[1] is not None:
            return False
    return True


#: `single_plan`'s direction for each solid built along its own direction of least overhang.
BEST_DIRECTION = "best"


def _unit_direction(direction) -> np.ndarray:
    d = np.asarray(direction, dtype=float)
    length = float(np.linalg.norm(d)) if d.shape == (3,) else 0.0
    if not np.isfinite(length) or length < ZERO_LENGTH:
        raise PlanError(f"build direction must be a non-zero 3-vector, got {list(direction)!r}")
    return d / length


def single_plan(shape, direction=(0.0, 0.0, 1.0)) -> BuildPlan:
    """A plan without splits: each solid of `shape` one sub-part built along `direction`
    (BEST_DIRECTION: each along its own direction of least overhang,
    `geometry/overhang.best_single_direction`; a list: one direction per solid), with the
    overhang it leaves (what supports would hold) measured."""
    from freecad_conformal.geometry.overhang import best_single_direction, overhang_area
    from freecad_conformal.geometry.solids import solids_of
    from freecad_conformal.decomposition.subparts import SubPart

    solids = solids_of(shape)
    if isinstance(direction, str) and direction == BEST_DIRECTION:
        directions = [best_single_direction(solid)[0] for solid in solids]
    elif isinstance(direction, list):
        if len(direction) != len(solids):
            raise PlanError(f"{len(direction)} build directions given for {len(solids)} solids")
        directions = [_unit_direction(d) for d in direction]
    else:
        directions = [_unit_direction(direction)] * len(solids)
    subparts = [SubPart(index=k, shape=solid, build_direction=d, volume=float(solid.Volume),
                        name=f"solid {k + 1}", solid_index=k, overhang_area=overhang_area(solid, d))
                for k, (solid, d) in enumerate(zip(solids, directions))]
    return BuildPlan(subparts=subparts, order=list(range(len(subparts))),
                     support_area_single_direction=float(sum(s.overhang_area for s in subparts)),
                     single_direction=directions[0])
