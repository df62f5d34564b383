"""Run-time estimate of a toolpath: trapezoidal acceleration with jerk-limited corners.

The model of Marlin-style firmwares (and of PrusaSlicer's own estimate, so the two compare):
every straight move accelerates at `acceleration` up to its feed; at a corner the speed may
jump by at most `jerk` (the velocity change 2·v·sin(θ/2) for a turn of θ at speed v), so a
sharp corner slows the nozzle down and a gentle one does not; a forward and a backward pass
make each junction speed reachable from its neighbours within the move lengths. Dwells
are added.
"""
from __future__ import annotations

import math

import numpy as np

from freecad_conformal.toolpath import KINDS, Toolpath, ToolpathError
from freecad_conformal.tolerances import COINCIDENT_POINTS

#: Marlin's and PrusaSlicer's default X/Y jerk (mm/s): the instantaneous speed change a
#: corner may take without slowing to it.
DEFAULT_JERK = 10.0

#: The toolpath metadata entry in which a plan records the jerk its times use: a toolpath
#: saved with the plan and posted later (`post`, the Post object) then says the same time.
JERK_KEY = "jerk"


def jerk_record(jerk: float) -> dict[str, str]:
    """The toolpath metadata recording `jerk` (its repr: `recorded_jerk` reads it back
    exactly)."""
    return {JERK_KEY: repr(float(jerk))}


def recorded_jerk(tp: Toolpath) -> float:
    """The jerk (mm/s) the plan that made `tp` estimated its time with (DEFAULT_JERK for a
    toolpath that records none, as those saved before it was recorded).

    Raises:
        ToolpathError: the recorded value is not a jerk (a finite speed above 0).
    """
    text = tp.metadata.get(JERK_KEY)
    if text is None:
        return DEFAULT_JERK
    try:
        value = float(text)
    except (TypeError, ValueError):
        value = math.nan
    if not (math.isfinite(value) and value > 0.0):
        raise ToolpathError(f"toolpath metadata {JERK_KEY!r} must be a jerk in mm/s (finite, "
                            f"above 0), got {text!r}")
    return value


def junction_speeds(directions: np.ndarray, speeds: np.ndarray, jerk: float) -> np.ndarray:
    """(m + 1,) speed at the start of each move and the end of the last (0 at both ends)."""
    m = len(speeds)
    junction = np.zeros(m + 1)
    if m > 1:
        cos = np.clip(np.einsum("ij,ij->i", directions[:-1], directions[1:]), -1.0, 1.0)
        half_sin = np.sqrt(np.maximum(0.0, 0.5 * (1.0 - cos)))
        limit = np.minimum(speeds[:-1], speeds[1:])
        with np.errstate(divide="ignore"):
            jerk_limit = np.where(half_sin > 0, jerk / (2.0 * half_sin), np.inf)
        junction[1:-1] = np.minimum(limit, jerk_limit)
    return junction


def move_times(lengths: np.ndarray, speeds: np.ndarray, junction: np.ndarray,
               acceleration: float) -> np.ndarray:
    """Trapezoid (or triangle) time of every move after making junctions reachable."""
    v = junction.tolist()
    two_a_l = (2.0 * acceleration * lengths).tolist()
    for i in range(len(two_a_l)):                       # forward: reachable by accelerating
        reach = math.sqrt(v[i] * v[i] + two_a_l[i])
        if v[i + 1] > reach:
            v[i + 1] = reach
    for i in range(len(two_a_l) - 1, -1, -1):           # backward: able to brake in time
        reach = math.sqrt(v[i + 1] * v[i + 1] + two_a_l[i])
        if v[i] > reach:
            v[i] = reach
    v = np.asarray(v)
    v0, v1, a = v[:-1], v[1:], acceleration
    accelerate = (speeds ** 2 - v0 ** 2) / (2 * a)
    brake = (speeds ** 2 - v1 ** 2) / (2 * a)
    cruise = lengths - accelerate - brake
    trapezoid = (speeds - v0) / a + (speeds - v1) / a + np.maximum(cruise, 0.0) / speeds
    peak = np.sqrt(np.maximum((2 * a * lengths + v0 ** 2 + v1 ** 2) / 2.0, 0.0))
    triangle = (peak - v0) / a + (peak - v1) / a
    return np.where(cruise >= 0, trapezoid, triangle)


def move_seconds(tp: Toolpath, acceleration: float, jerk: float = DEFAULT_JERK,
                 max_feed: float | None = None,
                 rapid_feed: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(seconds, segment index) of every move of `tp` that has a length (see estimate_time)."""
    lengths = tp.move_lengths()[1:]
    keep = lengths > COINCIDENT_POINTS
    segment = tp.segment_index[1:]
    feed = tp.feed[segment].astype(float)
    travel = tp.kind[segment] == KINDS.index("travel")
    if max_feed is not None:
        feed = np.where(travel, feed, np.minimum(feed, max_feed))
    if rapid_feed is not None:
        feed = np.where(travel, np.minimum(feed, rapid_feed), feed)
    lengths, speeds = lengths[keep], feed[keep] / 60.0
    if not len(lengths):
        return np.zeros(0), np.zeros(0, dtype=np.int64)
    steps = np.diff(tp.points, axis=0)[keep]
    directions = steps / lengths[:, None]
    junction = junction_speeds(directions, speeds, jerk)
    return move_times(lengths, speeds, junction, acceleration), segment[keep]


def estimate_time(tp: Toolpath, acceleration: float, jerk: float = DEFAULT_JERK,
                  max_feed: float | None = None, rapid_feed: float | None = None) -> float:
    """Seconds to run `tp` (tool-tip motion; feeds in mm/min, work moves capped at
    `max_feed`, travel moves at most `rapid_feed`: the machine's own limits)."""
    seconds, _ = move_seconds(tp, acceleration, jerk, max_feed, rapid_feed)
    return float(seconds.sum()) + sum(e.seconds for e in tp.events if e.action == "dwell")


def saved_toolpath_time(tp: Toolpath, machine) -> float:
    """Seconds to run a saved toolpath on `machine` as the plan that made it estimated
    them: at the jerk it recorded, with the machine's acceleration and feed limits (the
    `post` command and the Post object)."""
    return estimate_time(tp, machine.acceleration, recorded_jerk(tp),
                         max_feed=machine.max_feed, rapid_feed=machine.rapid_feed)
