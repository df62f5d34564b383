"""A BuildPlan's layers -> ordered 3D deposition paths -> the neutral toolpath.

Sub-parts are built in the plan's order; consecutive ones built in one direction from one
base level (a table's legs, solids standing side by side on the platform) are laid together,
layer by layer, as a planar slicer lays several objects and as the collision check of the
build order assumes (`planning.collision`). Inside a layer the nozzle travels straight in
the layer's top plane; between layers it first rises onto the next top plane along the new
normal; between sub-parts it takes the checked safe move of `paths.approach`. Each deposit
carries flow = the bead's cross-section (mm³/mm, `paths.bead`) for the layer's thickness;
at the model's spacing it fills the slab exactly.
Layers that would print (deposits and the travels between them, at nominal feeds) in under
`min_layer_time` are slowed as PrusaSlicer's cooling does: every deposit feed is capped at
one common speed (not below `min_speed`) so that the layer takes `min_layer_time`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from freecad_conformal.errors import PlanError
from freecad_conformal.paths import alternate
from freecad_conformal.paths.bead import bead_area
from freecad_conformal.paths.approach import (SAFE_MARGIN, UP, bounding_sphere, check_clearance,
                                              exit_distance, passes_near_up, transition)
from freecad_conformal.paths.fill2d import FillSettings, Path2D, nearest_first, ordered_fill
from freecad_conformal.paths.map3d import Path3D, bridge_regions, map_paths, skin_regions
from freecad_conformal.paths.stack_fill import StackFill, internal_bridge_area, stack_fills
from freecad_conformal.paths.support import StackSupport, SupportSettings, support_paths
from freecad_conformal.paths.support_plan import supports_of
from freecad_conformal.layers.model import Layer, base_level
from freecad_conformal.decomposition.subparts import BuildPlan
from freecad_conformal.toolpath import Toolpath, ToolpathBuilder
from freecad_conformal.tolerances import COINCIDENT_POINTS

#: Perimeter loops this short (mm) are printed at `Feeds.small_perimeter`: PrusaSlicer's
#: rule, a circle of 6.5 mm radius.
SMALL_PERIMETER_LENGTH = 2.0 * math.pi * 6.5
PERIMETER_ROLES = ("external_perimeter", "perimeter")

@dataclass
class Feeds:
    """Tool-tip speeds per role in mm/min (METHODS section 4: print 40/60, travel 150 mm/s)."""

    external_perimeter: float = 40.0 * 60
    perimeter: float = 40.0 * 60
    infill: float = 60.0 * 60
    solid_infill: float = 60.0 * 60
    travel: float = 150.0 * 60
    #: perimeter loops no longer than SMALL_PERIMETER_LENGTH (PrusaSlicer's small_perimeter_speed)
    small_perimeter: float = 15.0 * 60
    #: solid infill over sparse infill (an internal bridge) or over nothing; None: the solid
    #: infill feed
    bridge_infill: float | None = None
    #: support and its interface (PrusaSlicer's 60 mm/s, the interface at 100 % of it)
    support: float = 60.0 * 60

    def for_role(self, role: str) -> float:
        if role == "bridge_infill" and self.bridge_infill is None:
            return float(self.solid_infill)
        if role == "support_interface":
            return float(self.support)
        return float(getattr(self, role))

    @property
    def bridges_apart(self) -> bool:
        """Whether internal bridges (over sparse infill) are filled apart from the other
        solid infill: only when printed at another speed (the same speed gains nothing from
        a second zigzag). Bridges over nothing are always apart: their direction differs."""
        return self.for_role("bridge_infill") != self.for_role("solid_infill")

    def for_path(self, path: Path3D | Path2D) -> float:
        """The role's feed; small perimeter loops slower, so a small layer's walls can set
        (a planned path, or a fill's path the cost model times: paths/cost.py)."""
        feed = self.for_role(path.role)
        if path.closed and path.role in PERIMETER_ROLES and path.length <= SMALL_PERIMETER_LENGTH:
            feed = min(feed, self.small_perimeter)
        return feed

    def validate(self) -> None:
        for name in ("external_perimeter", "perimeter", "infill", "solid_infill", "travel",
                     "small_perimeter", "bridge_infill", "support"):
            value = self.for_role(name)
            if not (np.isfinite(value) and value > 0):
                raise PlanError(f"{name} feed must be > 0 mm/min, got {value!r}")


@dataclass
class PathSettings:
    """Fill, feeds, solid skins (layers), cooling slowdown (s, mm/min) and the tool number."""

    fill: FillSettings = field(default_factory=FillSettings)
    feeds: Feeds = field(default_factory=Feeds)
    top_layers: int = 3
    bottom_layers: int = 3
    min_layer_time: float = 5.0
    min_speed: float = 10.0 * 60
    tool_number: int = 1
    #: lay the layers of sub-parts ready together in turn where that beats slowing down
    alternate: bool = True
    #: support under the overhang a plan leaves (`paths.support`)
    support: SupportSettings = field(default_factory=SupportSettings)


@dataclass
class Assembly:
    """The toolpath and what it was made of (deposit paths for previews and statistics)."""

    toolpath: Toolpath
    paths: list[Path3D]
    travels: list[np.ndarray]
    moves_checked: int
    #: milling pass polylines of a hybrid plan (tool-tip points), for the preview
    cuts: list[np.ndarray] = field(default_factory=list)
    #: sub-part indices of each run laid in turn to cool (`alternation_sets`)
    alternated: list[list[int]] = field(default_factory=list)
    #: what became of the support asked for (`supports_of`), for the plan's notes
    support_notes: list[str] = field(default_factory=list)
    #: overhang (mm², summed over layers) laid as bridges with no support under it
    bridged_area: float = 0.0


def in_layer_travel(position: np.ndarray, start: np.ndarray, axis: np.ndarray,
                    new_layer: bool) -> np.ndarray:
    """Travel points (tool along `axis`) from `position` to a path's `start` within one
    sub-part: to a new layer's first path, up along the axis to its top plane first (never
    through the layer just laid), then across; inside a layer, straight (none when already
    there)."""
    if new_layer:
        rise = position + float((start - position) @ axis) * axis
        return np.array([rise, start])
    if np.linalg.norm(start - position) > COINCIDENT_POINTS:
        return start[None]
    return np.zeros((0, 3))


def layer_travel(position: np.ndarray, axis: np.ndarray, start: np.ndarray,
                 new_axis: np.ndarray, new_layer: bool) -> tuple[np.ndarray, np.ndarray]:
    """`in_layer_travel`'s points with their tool axes, the axis turning from `axis` to
    `new_axis` on the first move: through +Z half-way along it where the shortest turn passes
    close by (3-D layers tilted a fraction of a degree to either side of +Z), so that the
    turntable turns while the axis stands there (approach.POLE_CONE)."""
    points = in_layer_travel(position, start, new_axis, new_layer)
    axes = np.tile(new_axis, (len(points), 1))
    if len(points) and passes_near_up(axis, new_axis):
        points = np.vstack((0.5 * (position + points[0]), points))
        axes = np.vstack((UP, axes))
    return points, axes


#: The last few stacks' skins and bridges, with the layers and settings they were read for:
#: the plan choice costs the chosen plan's stacks (paths/cost.py) and the paths then fill the
#: same stacks (the bottle's skins: 0.47 s, read twice).
_SOLID_AREAS: list[tuple[tuple, PathSettings, bool, tuple[list, list]]] = []
SOLID_AREAS_KEPT = 4


def solid_areas(layers: Sequence[Layer], settings: PathSettings,
                rests_on_parent: bool) -> tuple[list, list]:
    """Per layer, its skin (the solid area) and the part of it filled apart as bridge
    infill (over sparse infill where bridges print at a speed of their own, and over
    nothing: `stack_fill.internal_bridge_area`): the fill's and the cost estimate's one
    reading of a stack (`paths.map3d`). Read once for the same layer
    objects and settings (callers do not change the lists returned)."""
    found = _known_areas(layers, settings, rests_on_parent)
    if found is not None:
        return found
    skins = skin_regions(layers, settings.top_layers, settings.bottom_layers, rests_on_parent)
    bridges = bridge_regions(layers, skins, internal_bridge_area(settings),
                             settings.fill.bead_width)
    found = (skins, bridges)
    _keep_areas(layers, settings, rests_on_parent, found)
    return found


def _known_areas(layers: Sequence[Layer], settings: PathSettings,
                 rests_on_parent: bool) -> tuple[list, list] | None:
    for known, known_settings, known_rests, found in _SOLID_AREAS:
        if (known_rests == rests_on_parent and len(known) == len(layers)
                and all(a is b for a, b in zip(known, layers)) and known_settings == settings):
            return found
    return None


def _keep_areas(layers: Sequence[Layer], settings: PathSettings, rests_on_parent: bool,
                found: tuple[list, list]) -> None:
    _SOLID_AREAS.append((tuple(layers), settings, rests_on_parent, found))
    del _SOLID_AREAS[:-SOLID_AREAS_KEPT]


def stacks_filled(stacks: Sequence[tuple[Sequence[Layer], bool]],
                  settings: PathSettings) -> list[StackFill]:
    """`stack_fills` of the stacks ((layers, rests on its parent)), with the skins and
    bridges already read for them, and keeping those it reads (`solid_areas`)."""
    known = [_known_areas(layers, settings, rests) for layers, rests in stacks]
    filled = stack_fills(stacks, settings, known)
    for (layers, rests), was, made in zip(stacks, known, filled):
        if was is None:
            _keep_areas(layers, settings, rests, (made.skins, made.bridges))
    return filled


def plan_paths(layers: Sequence[Layer], settings: PathSettings, rests_on_parent: bool,
               position: np.ndarray | None, filled: StackFill | None = None,
               support: StackSupport | None = None) -> list[list[Path3D]]:
    """Ordered 3D paths per layer of one sub-part, starting near `position`; `filled`: its
    stack's fills where already made (`stacks_filled`); `support`: its support areas, laid
    first on each layer (as PrusaSlicer does), nearest first."""
    if filled is None:
        filled = stacks_filled([(layers, rests_on_parent)], settings)[0]
    result = []
    for i, (layer, fill) in enumerate(zip(layers, filled.fills)):
        here = layer.frame.to_2d(position[None])[0] if position is not None else None
        below = []
        if support is not None and not (support.base[i].is_empty
                                        and support.interface[i].is_empty):
            below = nearest_first(support_paths(support.base[i], support.interface[i],
                                                settings.support, settings.fill.bead_width,
                                                layer.thickness, settings.fill.bead_model), here)
            here = below[-1].points[-1] if below else here
        paths = map_paths(layer, below + ordered_fill(fill, settings.fill, here))
        if paths:
            position = paths[-1].points[-1]
        result.append(paths)
    return result


#: Two layer tops closer than this (mm) along the build direction are one level.
SAME_LEVEL = 1e-6


def together(plan: BuildPlan, layers: dict[int, list[Layer]]) -> list[list]:
    """The plan's sub-parts in order, consecutive ones built in one direction from one base
    level grouped (see `planning.collision.concurrent`); sub-parts without layers dropped."""
    from freecad_conformal.geometry.collision import concurrent

    groups: list[list] = []
    for sub in plan.ordered():
        if not layers[sub.index]:
            continue
        head = groups[-1][0] if groups else None
        if head is not None and concurrent(head.build_direction, base_level(layers[head.index]),
                                           sub.build_direction, base_level(layers[sub.index])):
            groups[-1].append(sub)
        else:
            groups.append([sub])
    return groups


def _levels(per_member: list[list[list[Path3D]]], member_layers: list[list[Layer]]) -> list[list[Path3D]]:
    """The members' paths per layer merged level by level (layer tops along the group's
    direction, within SAME_LEVEL), each level's members in group order."""
    if len(per_member) == 1:
        return per_member[0]
    d = member_layers[0][0].top_normal
    items = sorted((float(layer.top_point @ d), k, paths)
                   for k, (paths_of, layers_of) in enumerate(zip(per_member, member_layers))
                   for layer, paths in zip(layers_of, paths_of))
    levels: list[list[tuple[int, list[Path3D]]]] = []
    level = None
    for height, k, paths in items:
        if level is None or height - level > SAME_LEVEL:
            levels.append([])
            level = height
        levels[-1].append((k, paths))
    # In group order within a level: tops a rounding apart (the table's legs, cut from one
    # solid, differ by 1e-13 mm) must not decide which leg is built first.
    return [[path for _, paths in sorted(members, key=lambda member: member[0]) for path in paths]
            for members in levels]


#: Bisection steps for the common cooling feed cap: 40 halvings of a feed range of
#: ~10⁴ mm/min leave it exact to far below 10⁻⁶ mm/min.
CAP_STEPS = 40


def _layer_seconds(paths: Sequence[Path3D], settings: PathSettings):
    """The layer's seconds with every deposit feed capped at a given feed (mm/min)."""
    feeds = [settings.feeds.for_path(p) for p in paths]
    gaps = sum(float(np.linalg.norm(b.points[0] - a.points[-1])) for a, b in zip(paths, paths[1:]))
    travel = 60.0 * gaps / settings.feeds.travel
    lengths = [p.length for p in paths]

    def seconds(cap: float) -> float:
        return travel + sum(60.0 * length / min(f, cap) for length, f in zip(lengths, feeds))

    return seconds


def _layer_feeds(paths: Sequence[Path3D], settings: PathSettings,
                 min_time: float | None = None) -> list[float]:
    """Deposit feeds; when the layer (deposits and the travels between them) would take
    under `min_time` (default `min_layer_time`; an alternated layer's: `paths.alternate`),
    every feed is capped at the one speed that makes it take that long, but not below
    `min_speed` (PrusaSlicer's cooling slowdown)."""
    min_time = settings.min_layer_time if min_time is None else min_time
    feeds = [settings.feeds.for_path(p) for p in paths]
    seconds = _layer_seconds(paths, settings)
    if not paths or seconds(max(feeds)) >= min_time:
        return feeds
    low = min(settings.min_speed, max(feeds))
    if seconds(low) <= min_time:
        return [min(f, low) for f in feeds]
    high = max(feeds)
    for _ in range(CAP_STEPS):              # seconds(cap) falls as the cap rises
        middle = 0.5 * (low + high)
        if seconds(middle) > min_time:
            low = middle
        else:
            high = middle
    return [min(f, high) for f in feeds]


class _Timing:
    """Each group's levels (those with paths) and their seconds, read once: nominal (what the
    cooling rule reads), nominal at the minimum speed, and at full feed with acceleration
    (what the estimate and the rounds' minimums read)."""

    def __init__(self, per_group: list, settings: PathSettings,
                 motion: tuple[float, float] | None) -> None:
        self._per_group, self._settings, self._motion = per_group, settings, motion
        self._nominal: dict[int, tuple[list[float], list[float]]] = {}
        self._full: dict[int, list[float]] = {}

    def levels(self, m: int) -> list[list[Path3D]]:
        return [paths for paths in self._per_group[m] if paths]

    def nominal(self, m: int) -> tuple[list[float], list[float]]:
        """Group m's levels' (nominal seconds, nominal seconds at the minimum speed)."""
        if m not in self._nominal:
            seconds = [_layer_seconds(paths, self._settings) for paths in self.levels(m)]
            self._nominal[m] = ([at(math.inf) for at in seconds],
                                [at(self._settings.min_speed) for at in seconds])
        return self._nominal[m]

    def full(self, m: int) -> list[float]:
        """Group m's levels' seconds at full feed with acceleration."""
        if m not in self._full:
            self._full[m] = [full_feed_seconds(paths, self._settings, self._motion)
                             for paths in self.levels(m)]
        return self._full[m]

    def slowed(self, m: int, seconds: list[float]) -> list[float]:
        """Group m's levels' `seconds` as the cooling rule slows each built alone."""
        return [alternate.slowed_seconds(at, nominal, slowest, self._settings.min_layer_time)
                for at, nominal, slowest in zip(seconds, *self.nominal(m))]


def alternation_sets(groups: list[list], per_group: list[list[list[Path3D]]],
                     settings: PathSettings, envelope,
                     motion: tuple[float, float] | None) -> list[tuple[list[int], list]]:
    """The groups (positions in `groups`) in runs laid in turn (`paths.alternate`), each with
    its steps (`_steps`); a group not worth alternating is a run of its own. A group joins
    the run before it when none of its sub-parts stands on the run's, its layers and the
    run's would be slowed down by more than alternating could save, that estimate pays for
    the turns, and the tool building either never meets the other (`motion`: the machine's
    acceleration, mm/s², and jerk, mm/s, the estimate's; None: no group is alternated).
    A run any of whose turns would pass too close to what is built (`check_clearance`) is
    built one group after another, as the plan would be without alternating."""
    timing = _Timing(per_group, settings, motion)
    runs: list[tuple[list[int], float]] = []
    for g in range(len(groups)):
        if runs and motion is not None and settings.alternate and settings.min_layer_time > 0:
            switch = _joined(runs[-1][0], g, groups, timing, settings, envelope, motion)
            if switch is not None:
                runs[-1] = (runs[-1][0] + [g], switch)
                continue
        runs.append(([g], 0.0))
    result = []
    for members, switch in runs:
        steps = _steps(members, per_group, switch, timing, settings)
        if len(members) == 1 or _turns_clear(members, steps, groups, per_group, envelope):
            result.append((members, steps))
        else:
            result.extend(([m], _steps([m], per_group, 0.0, timing, settings)) for m in members)
    return result


def _turns_clear(members: list[int], steps: list, groups: list[list], per_group: list,
                 envelope) -> bool:
    """Whether every turn of the run (its first move in included) keeps clear of the groups
    built before it, as `assemble` checks each move between sub-parts."""
    built = [sub.shape for m in range(members[0]) for sub in groups[m]]
    centre, radius = bounding_sphere(built + [sub.shape for m in members for sub in groups[m]])
    before = [paths for levels in per_group[:members[0]] for paths in levels if paths]
    position, axis = ((before[-1][-1].points[-1], before[-1][-1].axis) if before
                      else (None, None))
    previous = None
    for member, paths, _ in steps:
        start, new_axis = paths[0].points[0], paths[0].axis
        if position is not None and member != previous:
            points, axes = transition(position, axis, start, new_axis, centre, radius)
            try:
                check_clearance(np.vstack((position[None], points)),
                                np.vstack((axis[None], axes)), built, envelope, "", "")
            except PlanError:
                return False
        previous = member
        position, axis = paths[-1].points[-1], paths[-1].axis
    return True


def _joined(run: list[int], g: int, groups: list[list], timing: _Timing,
            settings: PathSettings, envelope, motion: tuple[float, float]) -> float | None:
    """The turn's seconds if group `g` is worth laying in turn with `run`, else None."""
    run_subs = {sub.index for m in run for sub in groups[m]}
    if any(sub.parent in run_subs for sub in groups[g]):
        return None
    members = run + [g]
    # Alternating saves at most the slowing down: most plans stop here, before any timing.
    nominal = [timing.nominal(m)[0] for m in members]
    slowed_nominal = [timing.slowed(m, seconds) for m, seconds in zip(members, nominal)]
    cooling = sum(map(sum, slowed_nominal)) - sum(map(sum, nominal))
    if cooling <= alternate.MIN_SAVING * sum(map(sum, slowed_nominal)):
        return None
    levels = [timing.levels(m) for m in members]
    shapes = [sub.shape for m in range(g + 1) for sub in groups[m]]
    ends = [(member[0][-1].points[-1], member[0][-1].axis) for member in levels]
    starts = [(member[0][0].points[0], member[0][0].axis) for member in levels]
    switch = alternate.switch_seconds(ends, starts, shapes, settings.feeds.travel, *motion)
    full = [timing.full(m) for m in members]
    slowed = [timing.slowed(m, seconds) for m, seconds in zip(members, full)]
    if not alternate.alternation_pays(full, slowed, switch, settings.min_layer_time):
        return None
    subs = [sub for m in members for sub in groups[m]]
    sizes = [len(groups[m]) for m in members]
    indices = [list(range(sum(sizes[:k]), sum(sizes[:k + 1]))) for k in range(len(members))]
    if not alternate.mutually_clear([sub.shape for sub in subs],
                                    [sub.build_direction for sub in subs], indices, envelope):
        return None
    return switch


def full_feed_seconds(paths: Sequence[Path3D], settings: PathSettings,
                      motion: tuple[float, float]) -> float:
    """A layer's seconds at full feed with acceleration (`motion`: mm/s², jerk mm/s): its
    deposits and the straight travels between them."""
    points, speeds = [paths[0].points[:1]], []
    for k, path in enumerate(paths):
        if k:
            speeds.append(settings.feeds.travel / 60.0)
            points.append(path.points[:1])
        points.append(path.points[1:])
        speeds.extend([settings.feeds.for_path(path) / 60.0] * (len(path.points) - 1))
    return alternate.polyline_seconds(np.vstack(points), speeds, *motion)


def _steps(members: list[int], per_group: list, switch: float, timing: _Timing,
           settings: PathSettings) -> list:
    """(group, the level's paths, its minimum nominal seconds or None for the usual rule) in
    building order: a lone group level by level, a run in rounds (`paths.alternate`): a
    layer is slowed by what its member's period falls short of the minimum layer time."""
    if len(members) == 1:
        return [(members[0], paths, None) for paths in per_group[members[0]]]
    order = alternate.rounds([len(timing.levels(m)) for m in members])
    full = [timing.full(members[m])[k] for m, k in order]
    minimums = alternate.step_minimums(full, order, switch, settings.min_layer_time)
    return [(members[m], timing.levels(members[m])[k],
             timing.nominal(members[m])[0][k] + minimum - seconds)
            for (m, k), minimum, seconds in zip(order, minimums, full)]


def assemble(plan: BuildPlan, layers: dict[int, list[Layer]], settings: PathSettings,
             envelope, motion: tuple[float, float] | None = None, **metadata: str) -> Assembly:
    """Build the toolpath of a whole plan (sub-parts in `plan.order`); with `motion` (the
    machine's acceleration, mm/s², and jerk, mm/s) sub-parts whose layers would be slowed
    down to cool are laid in turn where that is quicker (`alternation_sets`)."""
    settings.fill.validate()
    settings.feeds.validate()
    builder = ToolpathBuilder(**metadata)
    builder.event("tool_change", tool=settings.tool_number)
    width, travel_feed, tool = settings.fill.bead_width, settings.feeds.travel, settings.tool_number
    built: list = []
    names: list[str] = []
    all_paths: list[Path3D] = []
    travels: list[np.ndarray] = []
    position: np.ndarray | None = None
    axis: np.ndarray | None = None
    checked = 0

    def travel(points: np.ndarray, axes: np.ndarray) -> None:
        builder.add_segment(points, axes, kind="travel", feed=travel_feed, tool=tool)
        travels.append(np.vstack((position[None], points)) if position is not None else points)

    groups = together(plan, layers)
    # Every stack's fills at once, before the order that depends on the nozzle's path: the
    # child that shares them is started once for the plan.
    filled = iter(stacks_filled([(layers[sub.index], sub.parent is not None)
                                 for group in groups for sub in group], settings))
    supports, support_notes = supports_of(plan, layers, settings.support,
                                          settings.fill.bead_width, envelope)
    per_group = []
    for group in groups:
        per_group.append(_levels([plan_paths(layers[sub.index], settings, sub.parent is not None,
                                             position, next(filled), supports.get(sub.index))
                                  for sub in group],
                                 [layers[sub.index] for sub in group]))
        ends = [paths for paths in per_group[-1] if paths]
        if ends:
            position = ends[-1][-1].points[-1]
    position = None
    alternated: list[list[int]] = []
    for members, steps in alternation_sets(groups, per_group, settings, envelope, motion):
        shapes = [sub.shape for m in members for sub in groups[m]]
        sphere = bounding_sphere(built + shapes) if len(members) > 1 else None
        if len(members) > 1:
            alternated.append([sub.index for m in members for sub in groups[m]])
        previous = None
        for member, paths, minimum in steps:
            feeds = _layer_feeds(paths, settings, minimum)
            for k, (path, feed) in enumerate(zip(paths, feeds)):
                start, new_axis = path.points[0], path.axis
                if position is None:
                    lift = SAFE_MARGIN + bounding_sphere(shapes)[1]
                    travel(np.array([start + lift * new_axis, start]), np.array([new_axis, new_axis]))
                elif member != previous:
                    centre, radius = sphere or bounding_sphere(built)
                    points, axes = transition(position, axis, start, new_axis, centre, radius)
                    if sphere is None:      # an alternated run's turns were checked already
                        check_clearance(np.vstack((position[None], points)),
                                        np.vstack((axis[None], axes)), built, envelope,
                                        f"move to sub-part {path.subpart}", ", ".join(names))
                    checked += 1
                    travel(points, axes)
                else:
                    points, axes = layer_travel(position, axis, start, new_axis, k == 0)
                    if len(points):
                        travel(points, axes)
                previous = member
                builder.event("extruder_on")
                builder.add_segment(path.points[1:], new_axis, kind="deposit", feed=feed, tool=tool,
                                    flow=bead_area(path.width or width, path.thickness,
                                                   settings.fill.bead_model))
                builder.event("extruder_off")
                position, axis = path.points[-1], new_axis
                all_paths.append(path)
        built.extend(shapes)
        names.extend(f"sub-part {sub.index}" for m in members for sub in groups[m])
    if position is None:
        raise PlanError("the plan has no layer with material to deposit")
    centre, radius = bounding_sphere(built)
    retract = position + (exit_distance(position, axis, centre, radius + SAFE_MARGIN) + 1.0) * axis
    travel(retract[None], axis[None])
    return Assembly(builder.build(), all_paths, travels, checked, alternated=alternated,
                    support_notes=support_notes,
                    bridged_area=sum(s.bridged_area for s in supports.values()))

