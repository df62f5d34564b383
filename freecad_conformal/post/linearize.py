"""Toolpath -> machine blocks: inverse kinematics, subdivision to tolerance, collinear merge.

A machine interpolates its joints linearly between blocks, so a part-frame straight move
with rotary motion bends. Each such move is split into k equal parts in the part frame, k
estimated from the mid-chord deviation (which falls as 1/k²) and checked at ¼, ½ and ¾ of
every part, so the count stays close to the fewest blocks that meet the tolerance.
Afterwards consecutive moves of one segment that are collinear in joint space (weighted so
rotary motion counts as tip motion at the largest lever) become one block: a helix given as
"joint_linear" on a rotary mandrel comes out as one block per straight line unrolled.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from freecad_conformal.errors import PostError
from freecad_conformal.post.kinematics import forward, inverse, positions_for
from freecad_conformal.post.machine import LINEAR_NAMES, Machine
from freecad_conformal.tolerances import (
    DEFAULT_ANGULAR_TOLERANCE, DEFAULT_LINEAR_TOLERANCE, DIVISION_GUARD, LIMIT_SLACK,
    ROUNDING_SLACK, WRAP_MAX_STEP, ZERO_LENGTH)
from freecad_conformal.toolpath import INTERPOLATIONS, Toolpath

#: Joint-space deviation (as tip mm) allowed when merging collinear moves, as a fraction of
#: the tolerance: merging must not eat into the budget the subdivision already used.
MERGE_FRACTION = 0.01

#: Moves whose joints change by less than this (mm, or rad × lever) are dropped as empty.
ZERO_MOVE = 1e-9

#: A move shorter than this (mm) only reorients the tool: its axis is matched by parameter.
ZERO_CHORD = 1e-6
#: Unit vectors closer than this (sine of their angle) are blended linearly and normalised:
#: slerp's weights divide by the sine, which loses all digits near zero.
SLERP_AS_LERP = 1e-6

#: Sample parameters along each sub-move where the deviation is measured.
CHECK_PARAMETERS = (0.25, 0.5, 0.75)

#: A move whose deviation falls slower than parts^-MIN_ORDER when split (a smooth move
#: falls as parts^-2, one leaving a singular pose as parts^-1) has a jump in its joints.
MIN_ORDER = 0.25

#: More refined points than this in one round means the toolpath cannot be linearised
#: sensibly (about 150 bytes each while linearising: 20 million are 3 GB).
MAX_REFINED_POINTS = 20_000_000

#: The checks at CHECK_PARAMETERS can miss the peak of a lopsided deviation by a few
#: percent (an offset table-table B/C replayed at 0.010041 mm for 0.01): aim this much
#: below the tolerance so the true peak stays within it.
CHECK_MARGIN = 0.95

#: Refinement rounds; each multiplies the parts by the measured sqrt(deviation ratio), so
#: smooth moves settle in two rounds and only near-singular ones need more.
MAX_ROUNDS = 12


@dataclass
class Blocks:
    """Joint targets in program order; row 0 is the start pose (reached by a rapid)."""

    joints: np.ndarray       # (b, J) mm and rad, rotary axes unwound
    segment: np.ndarray      # (b,) toolpath segment of the move into each row
    tip_length: np.ndarray   # (b,) designed tool-tip path length of that move (mm)
    point: np.ndarray        # (b,) toolpath point the row ends at or before


def slerp(a: np.ndarray, b: np.ndarray, s: np.ndarray | float) -> np.ndarray:
    """Spherical interpolation of unit vectors row by row (normalised lerp when close)."""
    s = np.broadcast_to(np.asarray(s, dtype=float), (len(a),))[:, None]
    dot = np.clip(np.einsum("ij,ij->i", a, b), -1.0, 1.0)[:, None]
    angle = np.arccos(dot)
    sin = np.sin(angle)
    close = sin[:, 0] < SLERP_AS_LERP
    wa = np.where(close[:, None], 1.0 - s, np.sin((1.0 - s) * angle) / np.where(close[:, None], 1.0, sin))
    wb = np.where(close[:, None], s, np.sin(s * angle) / np.where(close[:, None], 1.0, sin))
    out = wa * a + wb * b
    return out / np.linalg.norm(out, axis=1)[:, None]


def joint_scale(machine: Machine, points: np.ndarray) -> np.ndarray:
    """Per-joint weights turning joint motion into tip motion: 1 for mm, lever for rad."""
    pivots = [np.linalg.norm(a.pivot) for a in machine.rotary]
    lever = float(np.max(np.linalg.norm(points, axis=1))) + max(pivots, default=0.0)
    return np.array([1.0] * 3 + [max(lever, 1.0)] * len(machine.rotary))


def linearize_by_tool(tp: Toolpath, machine: Machine,
                      tolerance: float = DEFAULT_LINEAR_TOLERANCE,
                      angular_tolerance: float = DEFAULT_ANGULAR_TOLERANCE) -> Blocks:
    """`linearize` each run of segments that use one tool with that tool's machine (head
    pivots measured from its tip); each run starts where the one before ended."""
    change = np.flatnonzero(np.diff(tp.tool)) + 1
    if not machine.head_axes or not machine.tool_lengths or len(change) == 0:
        return linearize(tp, machine.for_tool(int(tp.tool[0])), tolerance, angular_tolerance)
    bounds = np.concatenate(([0], change, [tp.segment_count]))
    starts = tp.segment_starts
    pieces, previous = [], None
    for a, b in zip(bounds[:-1].tolist(), bounds[1:].tolist()):
        first, last = int(starts[a]), int(starts[b])
        run = Toolpath(points=tp.points[first:last], axes=tp.axes[first:last],
                       segment_index=tp.segment_index[first:last] - a, kind=tp.kind[a:b],
                       feed=tp.feed[a:b], tool=tp.tool[a:b], flow=tp.flow[a:b],
                       interpolation=tp.interpolation[a:b], metadata=tp.metadata)
        blocks = linearize(run, machine.for_tool(int(tp.tool[a])), tolerance,
                           angular_tolerance, previous)
        pieces.append(Blocks(blocks.joints, blocks.segment + a, blocks.tip_length,
                             blocks.point + first))
        previous = blocks.joints[-1]
    return Blocks(*(np.concatenate([getattr(p, f) for p in pieces])
                    for f in ("joints", "segment", "tip_length", "point")))


def linearize(tp: Toolpath, machine: Machine, tolerance: float = DEFAULT_LINEAR_TOLERANCE,
              angular_tolerance: float = DEFAULT_ANGULAR_TOLERANCE,
              previous: np.ndarray | None = None) -> Blocks:
    """Turn a validated toolpath into joint blocks within `tolerance` (mm, rad), starting
    the branch choice from the joints `previous` (default: the machine's home)."""
    if not (tolerance > 0 and angular_tolerance > 0):
        raise PostError(f"tolerances must be > 0 (got {tolerance} mm, {angular_tolerance} rad)")
    part_linear = tp.interpolation[tp.segment_index] == INTERPOLATIONS.index("part_linear")
    part_linear[0] = False
    parts = np.ones(len(tp.points), dtype=np.int64)
    order = np.full(len(tp.points), 2.0)       # deviation ~ parts^-order (2: smooth chord)
    last_worst = np.full(len(tp.points), np.inf)
    last_parts = parts.copy()
    for _ in range(MAX_ROUNDS):
        points, axes, origin = _refine(tp, parts)
        joints, undefined = inverse(machine, points, axes, lambda i: tp.locate(int(origin[i])),
                                    previous=previous, with_undefined=True)
        if not machine.rotary:
            break
        points, axes, origin, joints = _turn_at_poles(machine, points, axes, origin, joints,
                                                      undefined, tolerance)
        ratio = _deviation_ratio(machine, points, axes, joints, tolerance, angular_tolerance)
        worst = np.zeros(len(tp.points))
        np.maximum.at(worst, origin[1:], ratio)
        worst[~part_linear] = 0.0
        if np.all(worst <= 1.0):
            break
        _refuse_jumps(tp, machine, parts, worst, last_worst, last_parts, points, joints, origin)
        new_parts = _grow(parts, order, worst, last_worst, last_parts)
        if int(new_parts.sum()) > MAX_REFINED_POINTS:
            i = int(np.argmax(new_parts))
            raise PostError(f"linearising within {tolerance} mm would take more than "
                            f"{MAX_REFINED_POINTS:,} blocks ({int(new_parts[i]):,} for the move "
                            f"into {tp.locate(i)} alone); loosen the tolerance or split the "
                            "toolpath")
        last_worst, last_parts, parts = np.where(worst > 1.0, worst, np.inf), parts, new_parts
    else:
        i = int(np.argmax(worst))
        raise PostError(f"cannot linearise the move into {tp.locate(i)} within {tolerance} mm / "
                        f"{math.degrees(angular_tolerance):.3f}° after {MAX_ROUNDS} rounds "
                        "(orientation too close to a singular pose?)")
    segment = tp.segment_index[origin]
    lengths = np.zeros(len(points))
    lengths[1:] = np.linalg.norm(np.diff(points, axis=0), axis=1)
    keep = _merge(joints, segment, joint_scale(machine, points), MERGE_FRACTION * tolerance)
    kept = np.flatnonzero(keep)
    cumulative = np.cumsum(lengths)
    tip = np.diff(np.concatenate(([0.0], cumulative[kept])))
    tip[0] = 0.0
    blocks = Blocks(joints=joints[kept], segment=segment[kept], tip_length=tip, point=origin[kept])
    return split_wrapped_turns(machine, blocks)


def split_wrapped_turns(machine: Machine, blocks: Blocks) -> Blocks:
    """Split blocks in which a `wrap` axis turns WRAP_MAX_STEP or more into equal parts.

    A wrapping controller reads angles in [0, 360) and takes the short way, so a block that
    turns half a turn or more would go the wrong way (a full turn would not move at all).
    The controller interpolates joints linearly, so equal joint-space parts follow exactly
    the path of the unsplit block.
    """
    wrapped = [3 + k for k, axis in enumerate(machine.rotary) if axis.wrap]
    if not wrapped or len(blocks.joints) < 2:
        return blocks
    delta = np.diff(blocks.joints, axis=0)
    turn = np.abs(delta[:, wrapped]).max(axis=1)
    parts = np.maximum(np.ceil(turn / WRAP_MAX_STEP * (1.0 + ROUNDING_SLACK)), 1).astype(np.int64)
    if np.all(parts == 1):
        return blocks
    move = np.repeat(np.arange(len(delta)), parts)                  # block each new row ends in
    first = np.cumsum(parts) - parts
    s = (np.arange(len(move)) - first[move] + 1) / parts[move]
    joints = np.vstack([blocks.joints[:1], blocks.joints[move] + s[:, None] * delta[move]])
    tip = np.concatenate(([0.0], blocks.tip_length[1:][move] / parts[move]))
    segment = np.concatenate((blocks.segment[:1], blocks.segment[1:][move]))
    point = np.concatenate((blocks.point[:1], blocks.point[1:][move]))
    return Blocks(joints=joints, segment=segment, tip_length=tip, point=point)


def _refuse_jumps(tp: Toolpath, machine: Machine, parts: np.ndarray, worst: np.ndarray,
                  last_worst: np.ndarray, last_parts: np.ndarray, points: np.ndarray,
                  joints: np.ndarray, origin: np.ndarray) -> None:
    """Refuse moves whose deviation does not fall as they are split: the joints jump there.

    That happens when a rotary limit forces the other orientation solution in the middle
    of a move (the tool would swing round); splitting more would only eat memory.
    """
    grown = (worst > 1.0) & np.isfinite(last_worst) & (parts >= 2 * last_parts)
    stuck = grown & (worst > last_worst * (last_parts / np.maximum(parts, 1)) ** MIN_ORDER)
    if not stuck.any():
        return
    move = int(np.flatnonzero(stuck)[np.argmax(worst[stuck])])
    rows = np.flatnonzero(origin == move)
    rows = rows[rows > 0]
    step = np.abs(joints[rows, 3:] - joints[rows - 1, 3:]).max(axis=1)
    row = int(rows[np.argmax(step)])
    jumps = ", ".join(f"{a.name} {math.degrees(joints[row - 1, 3 + k]):.1f}° -> "
                      f"{math.degrees(joints[row, 3 + k]):.1f}°" for k, a in enumerate(machine.rotary))
    where = f"cannot follow the move into {tp.locate(move)} on machine {machine.name}"
    outside = _outside_with_angles_kept(machine, points[row], joints[row - 1])
    if outside:
        tip = ", ".join(f"{c:.3f}" for c in points[row])
        travel = ", ".join(f"{a.name} [{a.limits[0]:g}, {a.limits[1]:g}]" for a in machine.linear)
        raise PostError(f"{where}: the tip at ({tip}) is outside the linear travel with the "
                        f"angles kept ({outside}); reaching it turns the rotary axes within the "
                        f"move ({jumps}), which would swing the part under the tool. Move the "
                        f"part toward the middle of the travel ({travel} mm) or use a machine "
                        "with more travel")
    limits = "; ".join(f"{a.name} limits [{math.degrees(a.limits[0]):g}, {math.degrees(a.limits[1]):g}]°"
                       for a in machine.rotary if a.limits is not None) or "no rotary limits"
    raise PostError(f"{where}: the rotary joints jump within it ({jumps}) and splitting it "
                    f"{int(parts[move])}-fold did not help: a rotary limit forces the other "
                    f"orientation solution there ({limits}); widen the limits or split the path "
                    "there")


def _outside_with_angles_kept(machine: Machine, point: np.ndarray, before: np.ndarray) -> str:
    """The linear axes out of limits, as "Y = 300.500 mm > 300", when the tip goes to `point`
    with the rotary angles of the pose `before`; "" when they all fit."""
    kept = before.copy()
    kept[:3] = positions_for(machine, point[None, :], kept[None, :])[0]
    words = []
    for k, axis in enumerate(machine.linear):
        low, high = axis.limits
        if kept[k] > high + LIMIT_SLACK:
            words.append(f"{axis.name} = {kept[k]:.3f} mm > {high:g}")
        elif kept[k] < low - LIMIT_SLACK:
            words.append(f"{axis.name} = {kept[k]:.3f} mm < {low:g}")
    return ", ".join(words)


def _grow(parts: np.ndarray, order: np.ndarray, worst: np.ndarray, last_worst: np.ndarray,
          last_parts: np.ndarray) -> np.ndarray:
    """More parts for moves over tolerance, using the convergence order seen so far.

    A chord's deviation falls as 1/k², but a move leaving a singular pose (C must turn
    while A is still tiny) only as 1/k; the observed order picks the right growth.
    """
    grow = worst > 1.0
    seen = grow & np.isfinite(last_worst) & (last_worst > worst) & (parts > last_parts)
    if np.any(seen):
        observed = np.log(last_worst[seen] / worst[seen]) / np.log(parts[seen] / last_parts[seen])
        order[seen] = np.clip(observed, 1.0, 2.0)   # updated in place for the next round
    new_parts = parts.copy()
    factor = np.maximum(worst[grow] ** (1.0 / order[grow]), 1.0)
    new_parts[grow] = np.maximum(parts[grow] + 1, np.ceil(parts[grow] * factor * 1.02))
    return new_parts


def _turn_at_poles(machine: Machine, points: np.ndarray, axes: np.ndarray, origin: np.ndarray,
                   joints: np.ndarray, undefined: np.ndarray, tolerance: float):
    """Leaving a singular pose (e.g. A = 0) with another C: turn C first, at the pole.

    At the pole C is free, so the turn does not change the tool axis; done in steps whose
    chord stays within `tolerance` at the tip's radius, with X, Y, Z following the part.
    Without it the whole turn would fall into the first piece of the move however finely
    that move is split.
    """
    delta = joints[1:, 3:] - joints[:-1, 3:]
    leaving = undefined[:-1] & ~undefined[1:] & (np.abs(delta) > ZERO_LENGTH)
    rows = np.flatnonzero(leaving.any(axis=1)) + 1
    if len(rows) == 0:
        return points, axes, origin, joints
    pieces = [(points, axes, origin, joints)]
    inserts = []
    for r in rows.tolist():
        turn = np.where(leaving[r - 1], delta[r - 1], 0.0)
        radius = max(float(np.linalg.norm(points[r - 1])) + max(
            (float(np.linalg.norm(a.pivot)) for a in machine.rotary), default=0.0), tolerance)
        step = 2.0 * math.acos(max(1.0 - tolerance / radius, -1.0))
        count = max(int(math.ceil(float(np.max(np.abs(turn))) / step)), 1)
        s = np.arange(1, count + 1) / count
        turned = np.repeat(joints[r - 1:r], count, axis=0)
        turned[:, 3:] += s[:, None] * turn
        repeated = np.repeat(points[r - 1:r], count, axis=0)
        turned[:, :3] = positions_for(machine, repeated, turned)
        inserts.append((r, repeated, np.repeat(axes[r - 1:r], count, axis=0),
                        np.full(count, origin[r]), turned))
    pieces = []
    last = 0
    for r, p, a, o, j in inserts:
        pieces.append((points[last:r], axes[last:r], origin[last:r], joints[last:r]))
        pieces.append((p, a, o, j))
        last = r
    pieces.append((points[last:], axes[last:], origin[last:], joints[last:]))
    return tuple(np.concatenate([piece[k] for piece in pieces]) for k in range(4))


def _refine(tp: Toolpath, parts: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Split the move into point i into parts[i] equal part-frame pieces."""
    if np.all(parts == 1):
        return tp.points, tp.axes, np.arange(len(tp.points))
    origin = np.repeat(np.arange(len(tp.points)), parts)
    first = np.cumsum(parts) - parts
    step = np.arange(len(origin)) - first[origin] + 1          # 1..parts within each move
    s = step / parts[origin]
    prev = np.maximum(origin - 1, 0)
    points = tp.points[prev] + (tp.points[origin] - tp.points[prev]) * s[:, None]
    axes = slerp(tp.axes[prev], tp.axes[origin], s)
    return points, axes, origin


def _deviation_ratio(machine: Machine, points: np.ndarray, axes: np.ndarray, joints: np.ndarray,
                     tolerance: float, angular_tolerance: float) -> np.ndarray:
    """Worst (deviation / tolerance) of each move into rows 1.. when joints move linearly.

    A move that turns no rotary joint and keeps its designed axis follows its chord exactly
    (the linear joints move the tip along a line the fixed rotations only turn): 0, without
    the forward kinematics (most of a 5-axis print's moves: CrankArm's post 2.9 -> 1.7 s)."""
    worst = np.zeros(len(points) - 1)
    rotary = slice(len(LINEAR_NAMES), None)
    turning = (np.any(joints[1:, rotary] != joints[:-1, rotary], axis=1)
               | np.any(axes[1:] != axes[:-1], axis=1))
    rows = np.flatnonzero(turning)
    if not len(rows):
        return worst
    a, b = points[rows], points[rows + 1]
    start, end = joints[rows], joints[rows + 1]
    chord = b - a
    length2 = np.maximum(np.einsum("ij,ij->i", chord, chord), DIVISION_GUARD)
    for s in CHECK_PARAMETERS:
        tip, axis = forward(machine, start + s * (end - start))
        t = np.clip(np.einsum("ij,ij->i", tip - a, chord) / length2, 0.0, 1.0)
        position = np.linalg.norm(tip - (a + t[:, None] * chord), axis=1)
        # the axis designed where the tip is; a pure reorientation (no chord) goes by s
        designed = slerp(axes[rows], axes[rows + 1], np.where(length2 > ZERO_CHORD ** 2, t, s))
        angle = np.arccos(np.clip(np.einsum("ij,ij->i", axis, designed), -1.0, 1.0))
        worst[rows] = np.maximum(worst[rows], np.maximum(position / tolerance,
                                                         angle / angular_tolerance))
    return worst / CHECK_MARGIN


def _merge(joints: np.ndarray, segment: np.ndarray, scale: np.ndarray, merge_tol: float) -> np.ndarray:
    """Rows to keep: drop empty moves, then interior rows collinear in joint space."""
    q = joints * scale
    keep = np.ones(len(q), dtype=bool)
    step = np.linalg.norm(np.diff(q, axis=0), axis=1)
    keep[1:] = step > ZERO_MOVE
    rows = np.flatnonzero(keep)
    if len(rows) < 3:
        return keep
    kq, kseg = q[rows], segment[rows]
    before, after = kq[1:-1] - kq[:-2], kq[2:] - kq[1:-1]
    same_segment = kseg[1:-1] == kseg[2:]
    forward_going = np.einsum("ij,ij->i", before, after) > 0
    candidate = same_segment & forward_going & (_line_distance(kq[:-2], kq[2:], kq[1:-1]) <= merge_tol)
    inner = np.ones(len(rows), dtype=bool)
    inner[1:-1] = ~candidate
    _restore_within_tolerance(kq, inner, merge_tol)
    keep[rows[~inner]] = False
    return keep


def _line_distance(start: np.ndarray, end: np.ndarray, point: np.ndarray) -> np.ndarray:
    chord = end - start
    length2 = np.maximum(np.einsum("ij,ij->i", chord, chord), DIVISION_GUARD)
    t = np.clip(np.einsum("ij,ij->i", point - start, chord) / length2, 0.0, 1.0)
    return np.linalg.norm(point - (start + t[:, None] * chord), axis=1)


def _restore_within_tolerance(q: np.ndarray, keep: np.ndarray, merge_tol: float) -> None:
    """Re-keep the worst dropped row of every merged run that strays over `merge_tol`.

    Locally collinear rows can drift over a long run (a gentle arc); like Douglas-Peucker
    restricted to the dropped rows, repeat until every run fits.
    """
    index = np.arange(len(q))
    while True:
        anchor = np.where(keep, index, 0)
        np.maximum.accumulate(anchor, out=anchor)
        following = np.where(keep, index, len(q) - 1)
        following = np.minimum.accumulate(following[::-1])[::-1]
        dropped = np.flatnonzero(~keep)
        if len(dropped) == 0:
            return
        deviation = _line_distance(q[anchor[dropped]], q[following[dropped]], q[dropped])
        worst = np.zeros(len(q))
        np.maximum.at(worst, anchor[dropped], deviation)
        over = (deviation > merge_tol) & (deviation >= worst[anchor[dropped]])
        if not over.any():
            return
        keep[dropped[over]] = True
