"""Toolpath + machine + dialect -> G-code text (the post-processor's entry point)."""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from freecad_conformal.errors import PostError
from freecad_conformal.fileio import write_text_atomic
from freecad_conformal.post.dialects import get_dialect
from freecad_conformal.post.dialects.base import Dialect, feed_number, number
from freecad_conformal.post.linearize import Blocks, linearize_by_tool
from freecad_conformal.post.machine import Machine
from freecad_conformal.tolerances import DEFAULT_ANGULAR_TOLERANCE, DEFAULT_LINEAR_TOLERANCE
from freecad_conformal.toolpath import KINDS, Event, Toolpath

#: Below this a joint is "not moving" in a block (mm or degrees): G-code keeps 4 decimals.
STILL = 1e-9


@dataclass
class PostResult:
    """The program text and what it was made from, for checks and reports."""

    text: str
    blocks: Blocks
    values: np.ndarray       # (b, J) as written: mm, degrees (wrapped where the machine wraps)
    rapid: np.ndarray        # (b,) row moved by G0
    names: tuple[str, ...]   # axis letters of the columns of `values`
    time_s: float            # estimated run time: the caller's, else the toolpath summary's


def machine_values(machine: Machine, joints: np.ndarray, wrap: bool = True) -> np.ndarray:
    """Joints (mm, rad unwound) -> G-code values (mm, degrees; [0, 360) for wrapped axes
    unless `wrap` is False)."""
    values = np.array(joints, dtype=float)
    values[:, 3:] = np.degrees(values[:, 3:])
    for k, axis in enumerate(machine.rotary):
        if axis.wrap and wrap:
            values[:, 3 + k] = np.mod(values[:, 3 + k], 360.0)
    return values


def post_toolpath(tp: Toolpath, machine: Machine, dialect: str | None = None,
                  tolerance: float = DEFAULT_LINEAR_TOLERANCE,
                  angular_tolerance: float = DEFAULT_ANGULAR_TOLERANCE,
                  relative_e: bool = True, time_s: float | None = None) -> PostResult:
    """Post-process a toolpath; raises ConformalError subclasses on bad input. `time_s` is
    the run time the caller estimated (a job's: paths/timing.estimate_time, with its jerk
    and the machine's feed limits), written in the header so the program says what the
    plan's summary and report say; None: the toolpath's own estimate (trapezoidal moves,
    corners not slowed down)."""
    if time_s is not None and not (math.isfinite(time_s) and time_s >= 0.0):
        raise PostError(f"estimated run time must be a finite number of seconds >= 0, got {time_s!r}")
    tp.validate()
    writer = get_dialect(dialect or machine.dialect, tolerance)
    blocks = linearize_by_tool(tp, machine, tolerance, angular_tolerance)
    values = machine_values(machine, blocks.joints)
    rapid = tp.kind[blocks.segment] == KINDS.index("travel")
    rapid[0] = True
    if machine.head_axes and machine.tool_lengths:
        # each tool's run starts with its own start pose (linearize_by_tool): reach it by G0
        tools = tp.tool[blocks.segment]
        rapid[1:] |= tools[1:] != tools[:-1]
    summary = tp.summary(acceleration=machine.acceleration, rapid_feed=machine.rapid_feed)
    if time_s is not None:
        summary = dataclasses.replace(summary, time_s=float(time_s))
    moves = _move_lines(tp, machine, writer, blocks, values, rapid, relative_e)
    lines = _header(tp, machine, writer, summary, tolerance, angular_tolerance, len(values))
    lines += writer.preamble(machine, relative_e)
    lines += writer.start(machine)
    events = _events_by_place(tp.events if writer.extrusion else implied_extruder_events(tp))
    first_tools = [e for e in events.pop((0, "before"), []) if e.action == "tool_change"]
    other_first = [e for e in tp.events if (e.segment, e.position) == (0, "before")
                   and e.action != "tool_change"]
    for event in first_tools:
        lines += writer.event(event, machine)
    names = machine.joint_names
    lines.append("G0 " + " ".join(f"{n}{number(v)}" for n, v in zip(names, values[0])))
    events[(0, "before")] = other_first
    bounds = np.searchsorted(blocks.segment[1:], np.arange(tp.segment_count + 1)) + 1
    changed_tool = False
    for segment in range(tp.segment_count):
        for event in events.get((segment, "before"), []):
            lines += writer.event(event, machine)
            changed_tool |= event.action == "tool_change"
        rows = moves[bounds[segment] - 1:bounds[segment + 1] - 1]
        if changed_tool and rows:
            # after a tool change (and its length offset) every axis is written again, so
            # the controller cannot keep an old position in the new tool's coordinates
            row = bounds[segment] - 1
            rows = [_full_move(rows[0], names, values[row + 1])] + rows[1:]
            changed_tool = False
        lines += rows
        for event in events.get((segment, "after"), []):
            lines += writer.event(event, machine)
            changed_tool |= event.action == "tool_change"
    lines += writer.end(machine)
    lines += writer.postamble(machine)
    return PostResult("\n".join(lines) + "\n", blocks, values, rapid, names, summary.time_s)


def _full_move(line: str, names: tuple[str, ...], row: np.ndarray) -> str:
    """`line` with every axis word, whether or not it changed."""
    prefix = line.split(" ")[0] if not line.startswith(("G93", "G94")) else " ".join(line.split(" ")[:2])
    rest = [w for w in line[len(prefix):].split() if w[0] not in names]
    return " ".join([prefix] + [f"{n}{number(v)}" for n, v in zip(names, row)] + rest)


def implied_extruder_events(tp: Toolpath) -> tuple[Event, ...]:
    """The toolpath's events, plus extruder on/off around each deposit run when it has no
    extruder event at all (a toolpath that switches the extruder itself is left alone).

    Dialects without E words drive the extruder from an output: deposit segments with the
    extruder never switched on would move without depositing while the header claims
    material.
    """
    if any(e.action in ("extruder_on", "extruder_off") for e in tp.events):
        return tp.events
    deposit = np.concatenate(([False], tp.kind == KINDS.index("deposit"), [False]))
    starts = np.flatnonzero(deposit[1:-1] & ~deposit[:-2])
    ends = np.flatnonzero(deposit[1:-1] & ~deposit[2:])
    implied = [Event(int(k), "before", "extruder_on") for k in starts]
    implied += [Event(int(k), "after", "extruder_off") for k in ends]
    # the explicit events of a place come first: a dwell before a run happens with it off
    return tuple(sorted(tp.events + tuple(implied),
                        key=lambda e: (e.segment, e.position == "after")))


def write_program(path: str | Path, result: PostResult) -> None:
    """Write atomically: the file appears whole or not at all."""
    write_text_atomic(path, result.text)


def _events_by_place(events: tuple[Event, ...]) -> dict[tuple[int, str], list[Event]]:
    places: dict[tuple[int, str], list[Event]] = {}
    for event in events:
        places.setdefault((event.segment, event.position), []).append(event)
    return places


def _header(tp: Toolpath, machine: Machine, writer: Dialect, summary, tolerance: float,
            angular_tolerance: float, blocks: int) -> list[str]:
    tools = sorted(set(tp.tool.tolist()) | {e.tool for e in tp.events if e.action == "tool_change"})
    seconds = int(round(summary.time_s))
    text = [
        "Conformal post-processor",
        f"part: {tp.metadata.get('part', 'unnamed')}",
        f"machine: {machine.name} [{Path(machine.source).stem}]",
        f"dialect: {writer.name}",
        f"tools: {', '.join(f'T{t}' for t in tools)}",
        f"estimated time: {seconds // 3600}:{seconds // 60 % 60:02d}:{seconds % 60:02d} "
        f"({summary.time_s:.1f} s)",
        f"material: {tp.metadata.get('material', 'unspecified')}, "
        f"{summary.material_volume:.3f} mm3 deposited"
        + (f" {writer.extrusion_note(machine)}" if summary.material_volume > 0 else "")
        + f", {summary.energy:.3f} J cured",
        f"tolerance: {tolerance:g} mm, {math.degrees(angular_tolerance):g} deg; "
        f"{tp.segment_count} segments, {len(tp.points)} points, {blocks} blocks",
    ]
    # what the planner says it cures (feature programs: widths, feeds, power per tool)
    text += [f"process: {note}" for note in tp.metadata.get("process", "").split("; ") if note]
    return [writer.comment(line) for line in text]


def _move_lines(tp: Toolpath, machine: Machine, writer: Dialect, blocks: Blocks,
                values: np.ndarray, rapid: np.ndarray, relative_e: bool) -> list[str]:
    """One line per block after the start row, vectorised over columns."""
    count = len(values) - 1
    if count <= 0:
        return []
    # motion from the unwound joints: a wrapped axis written 350 -> 10 turns 20°, not 340°
    delta = np.diff(machine_values(machine, blocks.joints, wrap=False), axis=0)
    linear = np.linalg.norm(delta[:, :3], axis=1)
    rotary = np.abs(delta[:, 3:]).max(axis=1) if machine.rotary else np.zeros(count)
    rotary_length = np.linalg.norm(delta[:, 3:], axis=1)
    segment = blocks.segment[1:]
    minutes = np.maximum.reduce([blocks.tip_length[1:] / tp.feed[segment],
                                 linear / machine.max_feed, rotary / machine.max_rotary_feed,
                                 np.full(count, STILL)])
    feed_rows = ~rapid[1:]
    inverse = feed_rows & writer.inverse_time & (rotary > STILL)
    controller_length = np.where(linear > STILL, linear, rotary_length)
    feed = np.where(inverse, 1.0 / minutes, controller_length / minutes)
    words = np.full(count, "", dtype=object)
    rounded = np.round(values, 4)
    for k, name in enumerate(machine.joint_names):
        changed = rounded[1:, k] != rounded[:-1, k]
        words[changed] += np.array([f" {name}{number(v)}" for v in values[1:, k][changed].tolist()],
                                   dtype=object)
    prefix, feed_words = _modes(inverse, feed_rows, feed)
    words = prefix + words + feed_words
    if writer.extrusion:
        words = words + _extrusion_words(tp, machine, blocks, relative_e)
    return words.tolist()


def _modes(inverse: np.ndarray, feed_rows: np.ndarray, feed: np.ndarray):
    """G0/G1 with G93/G94 switches, and F words (every inverse-time block, else on change)."""
    count = len(inverse)
    prefix = np.where(feed_rows, "G1", "G0").astype(object)
    feed_words = np.full(count, "", dtype=object)
    rows = np.flatnonzero(feed_rows)
    if len(rows) == 0:
        return prefix, feed_words
    mode = inverse[rows]
    switched = mode != np.concatenate(([False], mode[:-1]))
    prefix[rows[switched & mode]] = "G93 G1"
    prefix[rows[switched & ~mode]] = "G94 G1"
    # Feeds repeat (one per role and layer): each distinct value is written once, and
    # blocks are compared by which text they write (two values may write the same).
    values, where = np.unique(feed[rows], return_inverse=True)
    words, word_of_value = np.unique(np.array([" F" + feed_number(f) for f in values.tolist()]),
                                     return_inverse=True)
    word = word_of_value.ravel()[where.ravel()]
    changed = np.ones(len(rows), dtype=bool)
    changed[1:] = word[1:] != word[:-1]
    emit = mode | switched | changed
    feed_words[rows[emit]] = words.astype(object)[word[emit]]
    return prefix, feed_words


def _extrusion_words(tp: Toolpath, machine: Machine, blocks: Blocks, relative_e: bool) -> np.ndarray:
    segment = blocks.segment[1:]
    deposit = tp.kind[segment] == KINDS.index("deposit")
    area = math.pi * machine.filament_diameter ** 2 / 4.0
    extrude = np.where(deposit, tp.flow[segment] * blocks.tip_length[1:] / area, 0.0)
    shown = np.cumsum(extrude) if not relative_e else extrude
    words = np.full(len(segment), "", dtype=object)
    rows = np.flatnonzero(extrude > 0)
    words[rows] = [f" E{number(e, 5)}" for e in shown[rows].tolist()]
    return words
