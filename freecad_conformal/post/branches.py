"""Choosing among inverse-kinematics solutions: limits, least motion, unwinding.

Per point there are up to two orientation solutions ("branches"). The rule is greedy: keep
the branch of the previous point unless the other one is closer to the previous joints or
the kept one leaves the limits. Distances use wrapped angle differences, so the decision is
independent of how many turns an axis has unwound; the sequential part runs only at the
few points where the decision is not "stay", so long toolpaths stay vectorised.
"""
from __future__ import annotations

import math
from typing import Callable

import numpy as np

from freecad_conformal.errors import KinematicsError
from freecad_conformal.post.machine import Machine
from freecad_conformal.tolerances import LIMIT_SLACK

TWO_PI = 2.0 * math.pi
#: Joint motions (rad) equal to within rounding: the branch the path is on is kept.
SAME_MOTION = 1e-12


def _wrap(delta: np.ndarray) -> np.ndarray:
    """Angle differences into [-π, π)."""
    return (delta + math.pi) % TWO_PI - math.pi


def _short_range(machine: Machine) -> np.ndarray:
    """Axes whose limits span under one turn: their in-limit representative is unique."""
    return np.array([a.limits is not None and a.limits[1] - a.limits[0] < TWO_PI
                     for a in machine.rotary], dtype=bool)


def _representatives(machine: Machine, raw: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Shift short-range axes into [low, low + 2π); return values and in-limit flags."""
    values = raw.copy()
    valid = np.ones(raw.shape[:2], dtype=bool)
    for k, axis in enumerate(machine.rotary):
        if axis.limits is None or axis.limits[1] - axis.limits[0] >= TWO_PI:
            continue
        low, high = axis.limits
        shifted = low + (raw[..., k] - low + LIMIT_SLACK) % TWO_PI - LIMIT_SLACK
        values[..., k] = shifted
        valid &= np.isnan(shifted) | (shifted <= high + LIMIT_SLACK)
    return values, valid


def _ffill(values: np.ndarray, start: np.ndarray) -> np.ndarray:
    """Replace NaN (undefined angles) with the last defined value along axis 0."""
    out = values.copy()
    flat = out.reshape(len(out), -1)
    first = np.broadcast_to(start, out.shape[1:]).reshape(-1)
    for col in range(flat.shape[1]):
        column = flat[:, col]
        mask = np.isnan(column)
        if not mask.any():
            continue
        index = np.where(mask, 0, np.arange(len(column)))
        np.maximum.accumulate(index, out=index)
        filled = column[index]
        leading = mask & (np.cumsum(~mask) == 0)
        filled[leading] = first[col]
        flat[:, col] = filled
    return out


def _first_defined(values: np.ndarray, start: np.ndarray) -> np.ndarray:
    """Per column the first defined angle (start if none): a toolpath that begins at a
    singular pose takes the angle its first defined pose needs, instead of turning later
    while already tilted."""
    out = np.array(start, dtype=float)
    defined = ~np.isnan(values)
    for k in range(values.shape[1]):
        if defined[:, k].any():
            out[k] = values[np.argmax(defined[:, k]), k]
    return out


def _distance(a: np.ndarray, b: np.ndarray, short: np.ndarray) -> np.ndarray:
    delta = b - a
    delta = np.where(short, delta, _wrap(delta))
    return np.abs(delta).sum(axis=-1)


def choose_rotary(machine: Machine, candidates: np.ndarray, start: np.ndarray,
                  locate: Callable[[int], str]) -> np.ndarray:
    """Pick one solution per point and unwind: (n, branches, r) -> (n, r) radians."""
    n, branches, r = candidates.shape
    if r == 0:
        return np.zeros((n, 0))
    short = _short_range(machine)
    values, valid = _representatives(machine, candidates)
    if not valid.any(axis=1).all():
        i = int(np.argmin(valid.any(axis=1)))
        _raise_limits(machine, values[i, 0], locate(i))
    filled = _ffill(values, start)
    state = _branch_states(filled, valid, start, short)
    chosen = values[np.arange(n), state]
    chosen = _ffill(chosen, _first_defined(chosen, start))
    return _unwind(machine, chosen, start, short, locate)


def _branch_states(filled: np.ndarray, valid: np.ndarray, start: np.ndarray,
                   short: np.ndarray) -> np.ndarray:
    n, branches, _ = filled.shape
    if branches == 1:
        return np.zeros(n, dtype=np.int64)
    first_cost = np.where(valid[0], _distance(start, filled[0], short), np.inf)
    state0 = int(np.argmin(first_cost))
    previous = filled[:-1]
    same = _distance(previous, filled[1:], short)                       # (n-1, 2)
    cross = _distance(previous, filled[1:, ::-1], short)                # to the other branch
    valid_next = valid[1:]
    keep = valid_next & ((same <= cross + SAME_MOTION) | ~valid_next[:, ::-1])
    decisions = np.flatnonzero(~keep.all(axis=1)) + 1
    states = np.full(n, -1, dtype=np.int64)
    states[0] = state0
    current = state0
    for i in decisions.tolist():
        if not keep[i - 1, current]:
            current = 1 - current
        states[i] = current
    # between decision points the state stays what it was at the last decision
    index = np.where(states >= 0, np.arange(n), 0)
    np.maximum.accumulate(index, out=index)
    return states[index]


def _unwind(machine: Machine, chosen: np.ndarray, start: np.ndarray, short: np.ndarray,
            locate: Callable[[int], str]) -> np.ndarray:
    out = chosen.copy()
    for k, axis in enumerate(machine.rotary):
        if short[k]:
            continue
        column = chosen[:, k]
        steps = _wrap(np.diff(np.concatenate(([start[k]], column))))
        out[:, k] = start[k] + np.cumsum(steps)
        if axis.limits is not None:
            out[:, k] = _shift_into_limits(machine, k, out[:, k], locate)
    for k, axis in enumerate(machine.rotary):
        if axis.limits is None:
            continue
        low, high = axis.limits
        bad = (out[:, k] < low - LIMIT_SLACK) | (out[:, k] > high + LIMIT_SLACK)
        if bad.any():
            i = int(np.argmax(bad))
            _raise_limits(machine, out[i], locate(i))
    return out


def _shift_into_limits(machine: Machine, k: int, column: np.ndarray,
                       locate: Callable[[int], str]) -> np.ndarray:
    """Multi-turn limited axis: shift the whole unwound path by the whole turns that fit.

    A jump of whole turns in the middle of a path is not a move a machine can make (the
    tool would swing round while cutting), so the path either fits as a whole or is
    refused here, naming the axis, its limits and the travel it needs.
    """
    axis = machine.rotary[k]
    assert axis.limits is not None, "only limited axes are fitted by whole turns"
    low, high = axis.limits
    first, last = float(column.min()), float(column.max())
    fewest = math.ceil((low - LIMIT_SLACK - first) / TWO_PI)
    most = math.floor((high + LIMIT_SLACK - last) / TWO_PI)
    if fewest <= most:
        turns = min(max(0, fewest), most)
        return column + turns * TWO_PI
    travel = math.degrees(last - first)
    i, j = int(np.argmin(column)), int(np.argmax(column))
    where = (locate(min(i, j)), locate(max(i, j)))
    raise KinematicsError(
        f"rotary axis {axis.name} of machine {machine.name} would need {travel:.1f}° of travel "
        f"between {where[0]} and {where[1]}, but its limits [{math.degrees(low):g}, "
        f"{math.degrees(high):g}]° allow {math.degrees(high - low):g}°"
        + (" at whole-turn offsets that do not fit" if travel <= math.degrees(high - low) else "")
        + ": make the axis continuous if it can turn freely, or split the path")


def _raise_limits(machine: Machine, angles: np.ndarray, where: str) -> None:
    parts = []
    for value, axis in zip(angles, machine.rotary):
        limits = "continuous" if axis.limits is None else \
            f"limits [{math.degrees(axis.limits[0]):g}, {math.degrees(axis.limits[1]):g}]°"
        parts.append(f"{axis.name} = {math.degrees(value):.3f}° ({limits})")
    raise KinematicsError(f"orientation at {where} is outside the limits of machine "
                          f"{machine.name}: {'; '.join(parts)} and the other solution is too")
