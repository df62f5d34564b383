"""Cooling-aware alternation: layers of sub-parts that are ready together, built in turn.

A layer laid in less than the minimum layer time is slowed down so that it can cool before
the next one goes on top (`assemble._layer_feeds`). Where consecutive groups of sub-parts
in the build order (`assemble.together`) are all ready (none stands on another of them)
and the tool never meets one of them while it builds another (checked both ways, against
the whole of each: what is built of either at any moment is part of it), their layers may
be laid in turn instead, one layer of each per round, the table turning between them over
the safe sphere (`approach.transition`): the others' layers and the turns are the cooling
time. That is done only where it is estimated to be quicker than slowing down
(`alternation_pays`), so a plan whose layers are slow enough is built as before.

The schedule is pure arithmetic on seconds per layer: `rounds` orders the layers,
`step_minimums` says how long each must last for every member to get its minimum layer time
between its layers, and the toolpath (paths/assemble.py) follows them. `polyline_seconds`
and `switch_seconds` time layers and turns as paths/timing.py times the toolpath, and
`mutually_clear` is the collision check between members.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

from freecad_conformal.geometry.collision import CollisionChecker
from freecad_conformal.paths.approach import bounding_sphere, transition
from freecad_conformal.paths.timing import junction_speeds, move_times
from freecad_conformal.tolerances import COINCIDENT_POINTS

#: Alternating must save at least this share of the groups' sequential time: the estimate
#: times each turn once, between the members' first layers, and a slowed layer as taking
#: the slowdown's nominal seconds, so a saving smaller than its error is not worth the
#: extra turns of the table.
MIN_SAVING = 0.05


def rounds(counts: Sequence[int]) -> list[tuple[int, int]]:
    """(member, layer) in building order: one layer of each member per round, in member
    order; a member out of layers drops out and the others go on."""
    return [(member, layer) for layer in range(max(counts, default=0))
            for member, count in enumerate(counts) if layer < count]


def _switches(order: Sequence[tuple[int, int]]) -> list[bool]:
    """Per step, whether the table turns before it (another member was built just before)."""
    return [k > 0 and order[k - 1][0] != member for k, (member, _) in enumerate(order)]


def step_minimums(seconds: Sequence[float], order: Sequence[tuple[int, int]], switch: float,
                  min_time: float) -> list[float]:
    """Per step of `order`, how long its layer must take (s; its own `seconds` where that is
    enough) so that from its start to the start of the same member's next layer at least
    `min_time` passes, the turns (`switch` s each) and other members' layers included. A
    member's last layer counts what follows it to the end. One pass from the first step:
    slowing a layer only lengthens the periods of those before it."""
    durations = [float(s) for s in seconds]
    turns = _switches(order)
    for k, (member, _) in enumerate(order):
        following = next((j for j in range(k + 1, len(order)) if order[j][0] == member),
                         len(order))
        period = sum(durations[k:following]) + switch * sum(turns[k + 1:following + 1])
        if period < min_time:
            durations[k] += min_time - period
    return durations


def alternated_seconds(levels: Sequence[Sequence[float]], switch: float,
                       min_time: float) -> float:
    """Seconds to build the members' layers (`levels`: per member, seconds per layer at full
    feed) in rounds, slowed where a member's layers come round too soon."""
    order = rounds([len(member) for member in levels])
    seconds = [levels[member][layer] for member, layer in order]
    return (sum(step_minimums(seconds, order, switch, min_time))
            + switch * sum(_switches(order)))


def sequential_seconds(slowed: Sequence[Sequence[float]], switch: float) -> float:
    """Seconds to build the members one after the other (`slowed`: per member, each layer's
    seconds as the cooling rule slows it, `slowed_seconds`), turning once between them."""
    return sum(float(s) for member in slowed for s in member) + switch * max(len(slowed) - 1, 0)


def slowed_seconds(full: float, nominal: float, slowest: float, min_time: float) -> float:
    """A layer's seconds built alone: at full feed (`full`, with acceleration) unless its
    `nominal` seconds fall short of `min_time`, then about as long as the slowdown makes it,
    which goes no slower than the minimum speed (`slowest`: its nominal seconds at that)."""
    if nominal >= min_time:
        return full
    return max(full, min(min_time, slowest))


def alternation_pays(full: Sequence[Sequence[float]], slowed: Sequence[Sequence[float]],
                     switch: float, min_time: float) -> bool:
    """Whether laying the members in turn (`full`: per member, seconds per layer at full
    feed) saves at least MIN_SAVING of building them one after the other (`slowed`), with
    `switch` seconds per turn."""
    if len(full) < 2:
        return False
    sequential = sequential_seconds(slowed, switch)
    return alternated_seconds(full, switch, min_time) < (1.0 - MIN_SAVING) * sequential


def polyline_seconds(points, speeds, acceleration: float, jerk: float) -> float:
    """Seconds along the polyline `points` (N, 3), segment k at `speeds[k]` mm/s, from rest
    to rest (`paths.timing`: trapezoids, junctions limited by jerk)."""
    steps = np.diff(np.asarray(points, dtype=float), axis=0)
    lengths = np.linalg.norm(steps, axis=1)
    keep = lengths > COINCIDENT_POINTS
    if not keep.any():
        return 0.0
    lengths, speeds = lengths[keep], np.asarray(speeds, dtype=float)[keep]
    junction = junction_speeds(steps[keep] / lengths[:, None], speeds, jerk)
    return float(move_times(lengths, speeds, junction, acceleration).sum())


def switch_seconds(ends: Sequence, starts: Sequence, shapes: Sequence, travel_feed: float,
                   acceleration: float, jerk: float) -> float:
    """The longest turn between members (s at `travel_feed` mm/min): from each member's
    first layer's end (point, axis) to the next member's first layer's start, the last
    back to the first, over the safe sphere of `shapes` (`approach.transition`)."""
    centre, radius = bounding_sphere(list(shapes))
    longest = 0.0
    for k, (end, end_axis) in enumerate(ends):
        start, start_axis = starts[(k + 1) % len(starts)]
        points, _ = transition(end, end_axis, start, start_axis, centre, radius)
        move = np.vstack((end[None], points))
        longest = max(longest, polyline_seconds(move, np.full(len(move) - 1, travel_feed / 60.0),
                                                acceleration, jerk))
    return longest


def mutually_clear(shapes: Sequence, directions: Sequence, members: Sequence[Sequence[int]],
                   envelope) -> bool:
    """Whether the tool, building any of the sub-parts (`shapes`, built along `directions`;
    `members`: their indices per member), never meets a sub-part of another member
    (`geometry.collision`, against whole sub-parts)."""
    checker = CollisionChecker(list(shapes), list(directions), envelope)
    owner = {index: m for m, indices in enumerate(members) for index in indices}
    return not any(checker.hits(i, [j for j in owner if owner[j] != owner[i]]) for i in owner)
