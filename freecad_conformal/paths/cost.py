"""What a plan will cost before its paths are planned: print time and material per layer.

The fill of `paths.fill2d` is measured, not planned: per layer the perimeter loops and the
beads filling the gaps between them are the fill's own (`perimeter_walls`,
`gap_fill`), the infill areas its own split into solid and sparse (skins, pieces
under `solid_below_area`), and the infill rows its own scan lines (`scan_pieces` at the
fewest-turns angle), so lengths and material match the fill.
What is skipped is the expensive part: linking rows into zigzags, ordering, mapping to 3D
and building the toolpath. Times come from the motion model of `paths.timing` applied to
the pieces: every loop is run through the jerk and acceleration model edge by edge; every
infill row accelerates from and brakes to the speed of a zigzag's 90° turn; travels between
islands, loops and rows start and stop at rest. A layer shorter than the minimum layer
time is slowed as `paths.assemble` slows it (concurrent sub-parts share their levels), and
the moves between sub-parts follow `paths.approach.transition`.

The estimate is calibrated against the full plan's own estimate (`paths.timing`), within
`CALIBRATION_GOAL` on every sample part and every part of the shared set (a test).
"""
from __future__ import annotations

import math
import dataclasses
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np
import shapely
from shapely.geometry import Polygon

from freecad_conformal.decomposition.subparts import BuildPlan
from freecad_conformal.layers.model import Layer
from freecad_conformal.paths.approach import SAFE_MARGIN, bounding_sphere, transition
from freecad_conformal.paths.assemble import (PERIMETER_ROLES, SMALL_PERIMETER_LENGTH,
                                              PathSettings, solid_areas, together)
from freecad_conformal.paths.bead import bead_area, bead_spacing
from freecad_conformal.paths.map3d import air_at
from freecad_conformal.paths.stack_fill import SIMPLIFY_FRACTION, fill_key
from freecad_conformal.paths.fill2d import (Rows, Walls, fill_area, gap_fill, infill_areas,
                                            infill_rows, inset, island_walls, thin_wall_paths,
                                            valid_region)
from freecad_conformal.paths.scan import polygons_of, scan_pieces
from freecad_conformal.paths.timing import DEFAULT_JERK, junction_speeds, move_times

#: The estimate's promise: within 10 % of the full plan's time and material (issue 16).
CALIBRATION_GOAL = 0.10
#: A zigzag turns 90° into its connector and 90° out of it: the jerk model's corner speed.
ZIGZAG_TURN = math.pi / 2


@dataclass(frozen=True)
class Motion:
    """The machine's motion limits the full plan's estimate uses (mm/s, mm/s²)."""

    acceleration: float
    jerk: float = DEFAULT_JERK
    max_feed: float | None = None       # mm/min, caps work moves
    rapid_feed: float | None = None     # mm/min, caps travels

    @classmethod
    def of(cls, machine, jerk: float = DEFAULT_JERK) -> "Motion":
        return cls(machine.acceleration, jerk, machine.max_feed, machine.rapid_feed)

    def work_speed(self, feed: float) -> float:
        return (min(feed, self.max_feed) if self.max_feed else feed) / 60.0

    def travel_speed(self, feed: float) -> float:
        return (min(feed, self.rapid_feed) if self.rapid_feed else feed) / 60.0


@dataclass
class LayerCost:
    """One layer: seconds at full speed (with acceleration), the same without acceleration
    (what the cooling rule reads), material (mm³) and deposited length (mm)."""

    level: float
    seconds: float
    nominal_seconds: float
    travel_nominal_seconds: float
    material: float
    length: float


@dataclass
class SubPartCost:
    index: int
    layers: list[LayerCost] = field(default_factory=list)

    @property
    def material(self) -> float:
        return float(sum(c.material for c in self.layers))

    @property
    def seconds(self) -> float:
        return float(sum(c.seconds for c in self.layers))


@dataclass
class PlanCost:
    """The estimate of a whole plan: seconds and material (mm³), per sub-part too."""

    seconds: float
    material: float
    subparts: dict[int, SubPartCost]
    transition_seconds: float
    #: per level built, the seconds the minimum layer time added to it (0: none)
    cooling: list[float] = field(default_factory=list)
    #: seconds of each move from one group of sub-parts to the next
    moves: list[float] = field(default_factory=list)


def _segments_time(lengths: np.ndarray, speed: float, edge: float, motion: Motion) -> np.ndarray:
    """Time of straight moves at `speed` (mm/s) that start and end at `edge` mm/s."""
    v, a = speed, motion.acceleration
    edge = min(edge, v)
    ramp = (v * v - edge * edge) / a              # distance to reach v and brake back
    cruise = lengths >= ramp
    full = lengths / v + (v - edge) ** 2 / (a * v)
    peak = np.sqrt(np.maximum(a * lengths + edge * edge, 0.0))
    short = 2.0 * (peak - edge) / a
    return np.where(cruise, full, short)


def _ring_time(ring: np.ndarray, speed: float, motion: Motion) -> float:
    """A closed loop run through the jerk and acceleration model, starting from rest."""
    steps = np.diff(ring, axis=0)
    lengths = np.linalg.norm(steps, axis=1)
    keep = lengths > 0
    steps, lengths = steps[keep], lengths[keep]
    if not len(lengths):
        return 0.0
    directions = steps / lengths[:, None]
    speeds = np.full(len(lengths), speed)
    junction = junction_speeds(directions, speeds, motion.jerk)
    return float(move_times(lengths, speeds, junction, motion.acceleration).sum())


@dataclass
class _Tally:
    seconds: float = 0.0
    nominal: float = 0.0
    length: float = 0.0
    travel_count: int = 0
    travel_length: float = 0.0
    #: Σ length × width over the bead width (mm²): beads spread wider carry more per mm
    wider_area: float = 0.0
    #: mm³ that beads costed by their own cross-section carry beyond as long a bead of the
    #: settings' width (gap fill: one narrower than the layer is high is round, not `wider`)
    own_material: float = 0.0

    def work(self, length: float, seconds: float, feed_mm_s: float, wider: float = 0.0) -> None:
        self.seconds += seconds
        self.nominal += length / feed_mm_s
        self.length += length
        self.wider_area += length * wider

    def travel(self, length: float) -> None:
        self.travel_count += 1
        self.travel_length += length


def _perimeters(island: Polygon, settings: PathSettings, spacing: float, motion: Motion,
                tally: _Tally, external) -> Walls:
    width = settings.fill.bead_width
    walls = island_walls(island, width, settings.fill.perimeters, spacing, external)
    for depth, rings in enumerate(walls.depths):
        role = PERIMETER_ROLES[0] if depth == 0 else PERIMETER_ROLES[1]
        for ring in rings:
            length = float(np.linalg.norm(np.diff(ring, axis=0), axis=1).sum())
            feed = settings.feeds.for_role(role)
            if length <= SMALL_PERIMETER_LENGTH:
                feed = min(feed, settings.feeds.small_perimeter)
            speed = motion.work_speed(feed)
            tally.work(length, _ring_time(ring, speed, motion), speed, walls.width - width)
            tally.travel(spacing)
    return walls


def _thin_walls(island: Polygon, settings: PathSettings, motion: Motion, tally: _Tally,
                external) -> None:
    """The beads along the island's features narrower than a bead (`paths/thin_walls.py`),
    at the external perimeter's speed, each as wide as its feature."""
    for path in thin_wall_paths(island, settings.fill, external):
        speed = motion.work_speed(settings.feeds.for_role(path.role))
        tally.work(path.length, _ring_time(path.points, speed, motion), speed,
                   (path.width or 0.0) - settings.fill.bead_width)
        tally.travel(settings.fill.bead_width)


def _gap_fill(walls: Walls, settings: PathSettings, spacing: float, height: float,
              motion: Motion, tally: _Tally) -> list[Polygon]:
    """The beads along the gaps the perimeter loops leave (`fill2d.gap_fill`), each as wide
    as fills its gap and carrying its own cross-section, at the feed the paths give it
    (`paths.assemble.Feeds.for_path`); returns the gaps inside the innermost loops they
    fill."""
    fill = settings.fill
    usual = bead_area(fill.bead_width, height, fill.bead_model)
    paths, filled = gap_fill(walls, fill, spacing)
    for path in paths:
        speed = motion.work_speed(settings.feeds.for_path(path))
        tally.work(path.length, _ring_time(path.points, speed, motion), speed)
        tally.own_material += path.length * (
            bead_area(path.width or fill.bead_width, height, fill.bead_model) - usual)
        tally.travel(fill.bead_width)
    return filled


def _rows(area, laid: Rows, speed: float, motion: Motion, tally: _Tally) -> None:
    """The zigzag rows of `area`: each row accelerates from and brakes to the turn speed;
    the connectors between rows are one pitch each; a piece that does not follow on one of
    the row before (more pieces than there, or a row skipped) starts a chain: a travel."""
    pitch = laid.pitch
    pieces, _ = scan_pieces(area, pitch, laid.angle, laid.phase)
    if not len(pieces):
        return
    lengths = pieces[:, 2] - pieces[:, 1]
    turn = motion.jerk / (2.0 * math.sin(ZIGZAG_TURN / 2.0))
    rows, counts = np.unique(pieces[:, 0], return_counts=True)
    # A chain starts wherever a row has more pieces than the row before (or follows a gap).
    before = np.concatenate(([0], np.where(np.diff(rows) == 1, counts[:-1], 0)))
    chains = int(np.maximum(counts - before, 0).sum())
    links = len(pieces) - chains
    seconds = _segments_time(lengths, speed, turn, motion).sum()
    seconds += links * float(_segments_time(np.array([pitch]), speed, turn, motion)[0])
    tally.work(float(lengths.sum()) + links * pitch, float(seconds), speed, laid.wider)
    for _ in range(chains):
        tally.travel(math.sqrt(max(area.area, 0.0)) * 0.5)


def _infill(island: Polygon, walls: Walls, filled: list[Polygon], solid,
            settings: PathSettings, spacing: float, layer_index: int, motion: Motion,
            tally: _Tally, bridge=None, air=None) -> None:
    fill = settings.fill
    width = fill.bead_width
    inner = fill_area(island, len(walls.depths), walls.width, walls.spacing,
                      fill.infill_overlap, filled)
    if inner.is_empty:
        return
    for area, pitch, role, part, angle in infill_areas(inner, solid, bridge, fill, spacing,
                                                       air):
        if area.is_empty or pitch <= 0 or area.area < width * width:
            continue
        rows = infill_rows(area, pitch, role, part, fill, spacing, layer_index, angle)
        _rows(area, rows, motion.work_speed(settings.feeds.for_role(role)), motion, tally)


def _travel_seconds(length: float, motion: Motion, feed: float) -> float:
    if length <= 0:
        return 0.0
    return float(_segments_time(np.array([length]), motion.travel_speed(feed), 0.0, motion)[0])


def layer_cost(layer: Layer, skin, settings: PathSettings, motion: Motion,
               bridge=None, air=None) -> LayerCost:
    """Time and material of one layer filled as `paths.fill2d` fills it (`skin`: its solid
    area, from `paths.map3d.skin_regions`; `bridge`: the part filled as bridges, from
    `paths.map3d.bridge_regions`; `air`: its part over nothing, `paths.map3d.air_at`)."""
    width = settings.fill.bead_width
    spacing = bead_spacing(width, layer.thickness, settings.fill.bead_model)
    region = valid_region(layer.region.simplify(width * SIMPLIFY_FRACTION))
    solid = None if skin is None else valid_region(skin)
    tally = _Tally()
    islands = polygons_of(region)
    for island in islands:
        try:
            external = inset(island, 0.5 * width)
            walls = _perimeters(island, settings, spacing, motion, tally, external)
            _thin_walls(island, settings, motion, tally, external)
            filled = _gap_fill(walls, settings, spacing, layer.thickness, motion, tally)
            _infill(island, walls, filled, solid, settings, spacing, layer.index, motion,
                    tally, bridge, air)
        except shapely.errors.GEOSException:
            continue   # the fill raises a named error for this island; the estimate skips it
    level = _level(layer)
    if tally.length <= 0:
        return LayerCost(level, 0.0, 0.0, 0.0, 0.0, 0.0)   # nothing a bead can follow
    # From island to island, and from the last path to the next layer's first one.
    bounds = region.bounds if not region.is_empty else (0.0, 0.0, 0.0, 0.0)
    size = math.hypot(bounds[2] - bounds[0], bounds[3] - bounds[1])
    tally.travel(0.5 * size)
    if len(islands) > 1:
        centres = np.array([[p.centroid.x, p.centroid.y] for p in islands])
        hops = np.linalg.norm(np.diff(centres[np.argsort(centres[:, 0])], axis=0), axis=1)
        for hop in hops:
            tally.travel(float(hop))
    travel_feed = settings.feeds.travel
    travel_seconds = tally.travel_count * _travel_seconds(
        tally.travel_length / max(tally.travel_count, 1), motion, travel_feed)
    travel_nominal = 60.0 * tally.travel_length / travel_feed
    # A bead wider by Δw at the same height carries Δw·h more per mm (either bead model).
    material = (tally.length * bead_area(width, layer.thickness, settings.fill.bead_model)
                + tally.wider_area * layer.thickness + tally.own_material)
    return LayerCost(level, tally.seconds + travel_seconds, tally.nominal + travel_nominal,
                     travel_nominal, material, tally.length)


def subpart_cost(index: int, layers: Sequence[Layer], settings: PathSettings, motion: Motion,
                 rests_on_parent: bool, between: int = 1) -> SubPartCost:
    """Every layer's cost of one sub-part (skins as the fill sees them). `between` > 1:
    only every such layer of a run whose sections change evenly is filled and costed,
    those between read off the line between their costs (`_read_off_places`)."""
    skins, bridges = solid_areas(layers, settings, rests_on_parent)
    read_off = _read_off_places(layers, skins, bridges, between) if between > 1 else {}
    known: dict[tuple, LayerCost] = {}
    costs: dict[int, LayerCost] = {}
    for position, (layer, skin, bridge) in enumerate(zip(layers, skins, bridges)):
        if position in read_off:
            continue
        # A prism's layers repeat (the table's legs: one region for hundreds of layers):
        # a layer the same as one costed already, in everything the fill reads, costs the
        # same at its own level.
        air = air_at(layers, position, bridge, settings.fill.bead_width)
        key = fill_key(layer.region, skin, bridge, layer, air)
        same = known.get(key)
        if same is None:
            costs[position] = known[key] = layer_cost(layer, skin, settings, motion, bridge,
                                                      air)
        else:
            costs[position] = dataclasses.replace(same, level=_level(layer))
    for position, (before, after) in read_off.items():
        costs[position] = _read_off(layers[position], costs[before], costs[after],
                                    (position - before) / (after - before))
    return SubPartCost(index, [costs[position] for position in range(len(layers))])


#: A layer is read off the line between two filled ones when its area, skin area and bridge
#: area lie within this share of its area from the line, and its outline length within
#: this share of its length: the section changes evenly, and so do its loops, rows and
#: their times (a wedge's, a cone's, a tilted cylinder's).
EVEN_CHANGE = 0.01


def _read_off_places(layers: Sequence[Layer], skins: list, bridges: list,
                     between: int) -> dict[int, tuple[int, int]]:
    """{position: (filled before, filled after)} of the layers read off instead of filled.
    In each run of layers with one island count, and skin (or bridge) in all or none, every
    `between`-th layer and the last are filled; a layer between is read off where it lies
    on the line between them (EVEN_CHANGE)."""
    measures = np.array([(layer.region.area, layer.region.length, _area_of(skin),
                          _area_of(bridge)) for layer, skin, bridge in zip(layers, skins, bridges)])
    kinds = [(len(polygons_of(layer.region)), skin > 0, bridge > 0)
             for layer, (_, _, skin, bridge) in zip(layers, measures)]
    found: dict[int, tuple[int, int]] = {}
    start = 0
    while start < len(layers):
        end = start
        while end + 1 < len(layers) and kinds[end + 1] == kinds[start]:
            end += 1
        filled = sorted(set(range(start, end + 1, between)) | {end})
        for before, after in zip(filled, filled[1:]):
            for position in range(before + 1, after):
                share = (position - before) / (after - before)
                line = (1 - share) * measures[before] + share * measures[after]
                area, length = measures[position, :2]
                room = EVEN_CHANGE * np.array([area, length, area, area])
                if np.all(np.abs(measures[position] - line) <= room):
                    found[position] = (before, after)
        start = end + 1
    return found


def _area_of(region) -> float:
    return 0.0 if region is None or region.is_empty else float(region.area)


def _read_off(layer: Layer, before: LayerCost, after: LayerCost, share: float) -> LayerCost:
    """`layer`'s cost on the line from `before` (share 0) to `after` (share 1)."""
    def line(name: str) -> float:
        return (1 - share) * getattr(before, name) + share * getattr(after, name)

    return LayerCost(_level(layer), line("seconds"), line("nominal_seconds"),
                     line("travel_nominal_seconds"), line("material"), line("length"))


def _level(layer: Layer) -> float:
    """Where a layer's top lies along its own normal (levels are compared across
    sub-parts built together)."""
    return float(layer.top_point @ layer.top_normal)


#: Layer tops of concurrent sub-parts closer than this (mm) are one level (paths.assemble).
SAME_LEVEL = 1e-6


def _cooled(costs: list[LayerCost], settings: PathSettings) -> float:
    """Seconds of one level (the layers of concurrent sub-parts at one height), slowed as
    `paths.assemble._layer_feeds` slows a level under the minimum layer time: deposits
    capped at one speed, not below `min_speed`."""
    seconds = sum(c.seconds for c in costs)
    nominal = sum(c.nominal_seconds for c in costs)
    if nominal >= settings.min_layer_time or nominal <= 0:
        return seconds
    travel = sum(c.travel_nominal_seconds for c in costs)
    slowest = travel + 60.0 * sum(c.length for c in costs) / settings.min_speed
    return max(seconds, min(settings.min_layer_time, slowest))


def plan_cost(plan: BuildPlan, layers: dict[int, list[Layer]], settings: PathSettings,
              motion: Motion, between: int = 1) -> PlanCost:
    """Time and material of building `plan` with `layers`, without planning paths
    (`between`: see `subpart_cost`)."""
    subparts = {sub.index: subpart_cost(sub.index, layers[sub.index], settings, motion,
                                        sub.parent is not None, between)
                for sub in plan.ordered() if layers[sub.index]}
    seconds = 0.0
    moves = 0.0
    cooling: list[float] = []
    between: list[float] = []
    built: list = []
    previous = None
    for group in together(plan, layers):
        levels: list[tuple[float, list[LayerCost]]] = []
        for cost in sorted((c for sub in group for c in subparts[sub.index].layers),
                           key=lambda c: c.level):
            if levels and cost.level - levels[-1][0] <= SAME_LEVEL:
                levels[-1][1].append(cost)
            else:
                levels.append((cost.level, [cost]))
        cooled = [_cooled(costs, settings) for _, costs in levels]
        cooling.extend(slow - sum(c.seconds for c in costs)
                       for slow, (_, costs) in zip(cooled, levels))
        seconds += sum(cooled)
        first = layers[group[0].index][0]
        start = _centre_3d(first)
        axis = np.asarray(first.top_normal, dtype=float)
        if previous is None:
            lift = SAFE_MARGIN + bounding_sphere([sub.shape for sub in group])[1]
            moves += 2.0 * _travel_seconds(lift, motion, settings.feeds.travel)
        else:
            centre, radius = bounding_sphere(built)
            points, _ = transition(previous[0], previous[1], start, axis, centre, radius)
            path = np.vstack((previous[0][None], points))
            lengths = np.linalg.norm(np.diff(path, axis=0), axis=1)
            between.append(sum(_travel_seconds(float(x), motion, settings.feeds.travel)
                               for x in lengths))
            moves += between[-1]
        last = layers[group[-1].index][-1]
        previous = (_centre_3d(last), np.asarray(last.top_normal, dtype=float))
        built.extend(sub.shape for sub in group)
    material = float(sum(cost.material for cost in subparts.values()))
    return PlanCost(seconds + moves, material, subparts, moves, cooling, between)


def _centre_3d(layer: Layer) -> np.ndarray:
    centroid = layer.region.centroid
    return layer.to_3d(np.array([[centroid.x, centroid.y]]))[0]
