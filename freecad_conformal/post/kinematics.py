"""Forward and inverse kinematics for machines described as data (`post.machine`).

Joint vectors are (X, Y, Z, rotary...) in mm and radians, rotary axes in machine order.
Orientation: R_table(θ) · axis_part = R_head(φ) · tool_direction, where each side's
rotations compose from the machine base outward. With two rotary axes this is the classic
"two rotations take one vector onto another" problem (Paden-Kahan subproblem 2), which has
two solutions; with one it has at most one; with none the axis must already match.
Position: the tip in the machine frame is M_table(θ)·p = (X, Y, Z) + head_offset(φ).
"""
from __future__ import annotations

from typing import Callable

import numpy as np

from freecad_conformal.errors import KinematicsError
from freecad_conformal.post.branches import choose_rotary
from freecad_conformal.post.machine import Machine, RotaryAxis
from freecad_conformal.tolerances import AXIS_UNIT_TOLERANCE, LIMIT_SLACK, PARALLEL_COS_SLACK

#: Below this |sin| the tool axis is parallel to a rotary axis and that axis' angle is
#: undefined (e.g. A ≈ 0 on an A/C table): keep its previous value. 1e-9 rad of tool axis
#: is far below any angular tolerance, so ignoring the angle there costs nothing.
SINGULAR_SIN = 1e-9

#: An axis orientation that misses the reachable cone by more than this is an error.
#: 1e-6 rad is the accuracy of a toolpath written with 7 significant digits.
REACH_TOLERANCE = 1e-6

#: Values tried for a free rotary angle (a tool axis along that rotary axis) when the one
#: kept puts X, Y or Z out of limits: every 5°, relative to the kept value.
FREE_ANGLE_STEPS = np.radians(np.arange(5.0, 360.0, 5.0) - np.where(np.arange(5.0, 360.0, 5.0) > 180.0, 360.0, 0.0))

Locator = Callable[[int], str]


def rotate(vectors: np.ndarray, axis: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """Rotate (n, 3) vectors about the unit `axis` by (n,) angles (Rodrigues' formula)."""
    cos = np.cos(angles)[:, None]
    sin = np.sin(angles)[:, None]
    return (vectors * cos + np.cross(axis, vectors) * sin
            + np.outer(vectors @ axis, axis) * (1.0 - cos))


def _rotate_about(points: np.ndarray, axis: RotaryAxis, angles: np.ndarray) -> np.ndarray:
    return axis.pivot + rotate(points - axis.pivot, axis.direction, angles)


def _angles(machine: Machine, joints: np.ndarray, axes: tuple[RotaryAxis, ...]) -> list[np.ndarray]:
    names = machine.joint_names
    return [joints[:, names.index(a.name)] for a in axes]


def head_offset(machine: Machine, joints: np.ndarray) -> np.ndarray:
    """(n, 3) tool-tip offset from the commanded X, Y, Z caused by head rotations."""
    offset = np.zeros((len(joints), 3))
    for axis, angle in reversed(list(zip(machine.head_axes, _angles(machine, joints, machine.head_axes)))):
        offset = _rotate_about(offset, axis, angle)
    return offset


def forward(machine: Machine, joints: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Joint vectors (n, J) -> tool-tip points and unit tool axes in the part frame."""
    joints = np.atleast_2d(np.asarray(joints, dtype=float))
    tip = joints[:, :3] + head_offset(machine, joints)
    axis = np.broadcast_to(machine.tool_direction, tip.shape).copy()
    for head, angle in reversed(list(zip(machine.head_axes, _angles(machine, joints, machine.head_axes)))):
        axis = rotate(axis, head.direction, angle)
    for table, angle in zip(machine.table_axes, _angles(machine, joints, machine.table_axes)):
        tip = _rotate_about(tip, table, -angle)
        axis = rotate(axis, table.direction, -angle)
    return tip, axis


def table_transform(machine: Machine, joints: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Part-frame points -> machine frame for the table angles in `joints`."""
    out = np.array(points, dtype=float)
    for table, angle in reversed(list(zip(machine.table_axes, _angles(machine, joints, machine.table_axes)))):
        out = _rotate_about(out, table, angle)
    return out


def _angle_between(omega: np.ndarray, source: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Angle rotating `source` onto `target` about `omega` (subproblem 1); NaN if undefined."""
    s = source - np.outer(source @ omega, omega)
    t = target - np.outer(target @ omega, omega)
    angle = np.arctan2(np.cross(s, t) @ omega, np.einsum("ij,ij->i", s, t))
    undefined = np.linalg.norm(s, axis=1) < SINGULAR_SIN
    angle[undefined] = np.nan
    return angle


def _orientation_problem(machine: Machine, axes: np.ndarray):
    """Map the machine's rotary layout onto Rot(w1, x1) Rot(w2, x2) p = q.

    Returns (w1, w2, p, q, order, signs): joint angle k = signs[k] * x[order[k]].
    """
    tables, heads = machine.table_axes, machine.head_axes
    home = np.broadcast_to(machine.tool_direction, axes.shape)
    names = [a.name for a in machine.rotary]
    if len(tables) == 2:
        first, second, p, q, signs = tables[0], tables[1], axes, home, (1.0, 1.0)
    elif len(heads) == 2:
        first, second, p, q, signs = heads[0], heads[1], home, axes, (1.0, 1.0)
    else:
        first, second, p, q, signs = heads[0], tables[0], axes, home, (-1.0, 1.0)
    order = [names.index(first.name), names.index(second.name)]
    return first.direction, second.direction, p, q, order, signs


def rotary_candidates(machine: Machine, axes: np.ndarray, locate: Locator) -> np.ndarray:
    """(n, branches, r) rotary angles (rad, NaN where undefined) that orient the tool.

    Solved once per run of equal consecutive axes: a layer's paths share one axis, and
    solving each point took 0.5 s of CrankArm's post (2.4 s). Raises KinematicsError naming
    the first point whose axis the machine cannot reach.
    """
    if len(axes) < 2:
        return _rotary_candidates(machine, axes, locate)
    starts = np.flatnonzero(np.concatenate(([True], (axes[1:] != axes[:-1]).any(axis=1))))
    if len(starts) == len(axes):
        return _rotary_candidates(machine, axes, locate)
    runs = np.diff(np.append(starts, len(axes)))
    solved = _rotary_candidates(machine, axes[starts], lambda i: locate(int(starts[i])))
    return np.repeat(solved, runs, axis=0)


def _rotary_candidates(machine: Machine, axes: np.ndarray, locate: Locator) -> np.ndarray:
    """`rotary_candidates`, each axis solved."""
    n, r = len(axes), len(machine.rotary)
    if r == 0:
        miss = np.arccos(np.clip(axes @ machine.tool_direction, -1.0, 1.0))
        _raise_unreachable(miss > REACH_TOLERANCE, axes, locate, machine, "has no rotary axis")
        return np.zeros((n, 1, 0))
    if r == 1:
        rot = machine.rotary[0]
        sign = 1.0 if rot.on == "table" else -1.0
        home = np.broadcast_to(machine.tool_direction, axes.shape)
        miss = np.abs(axes @ rot.direction - machine.tool_direction @ rot.direction)
        _raise_unreachable(miss > REACH_TOLERANCE, axes, locate, machine,
                           f"keeps the axis component along {rot.name} fixed")
        angle = sign * _angle_between(rot.direction, axes, home)
        return angle[:, None, None]
    w1, w2, p, q, order, signs = _orientation_problem(machine, axes)
    c12 = float(w1 @ w2)
    cross = np.cross(w1, w2)
    if np.linalg.norm(cross) < PARALLEL_COS_SLACK:
        raise KinematicsError(f"machine {machine.name}: rotary axes {machine.rotary[0].name} and "
                              f"{machine.rotary[1].name} are parallel; cannot orient the tool")
    w2p, w1q = p @ w2, q @ w1
    alpha = (w1q - c12 * w2p) / (1.0 - c12 * c12)
    beta = (w2p - c12 * w1q) / (1.0 - c12 * c12)
    gamma2 = (1.0 - alpha ** 2 - beta ** 2 - 2.0 * alpha * beta * c12) / float(cross @ cross)
    _raise_unreachable(gamma2 < -2.0 * REACH_TOLERANCE, axes, locate, machine,
                       "cannot tilt that far with its rotary axes")
    gamma = np.sqrt(np.clip(gamma2, 0.0, None))
    out = np.empty((n, 2, 2))
    for branch, sign in enumerate((1.0, -1.0)):
        z = np.outer(alpha, w1) + np.outer(beta, w2) + np.outer(sign * gamma, cross)
        z = z / np.linalg.norm(z, axis=1)[:, None]
        x2 = _angle_between(w2, p, z)
        x1 = _angle_between(w1, z, q)
        out[:, branch, order[0]] = signs[0] * x1
        out[:, branch, order[1]] = signs[1] * x2
    return out


def _raise_unreachable(bad: np.ndarray, axes: np.ndarray, locate: Locator, machine: Machine,
                       reason: str) -> None:
    if np.any(bad):
        i = int(np.argmax(bad))
        raise KinematicsError(f"tool axis {np.round(axes[i], 6).tolist()} at {locate(i)} is not "
                              f"reachable: machine {machine.name} {reason}")


def unit_axes(axes: np.ndarray, locate: Locator) -> np.ndarray:
    """Axes scaled to unit length; far from unit (AXIS_UNIT_TOLERANCE) is an error.

    The orientation solution assumes unit vectors: an axis of length 0.9999999 would come
    out tilted by about sqrt(2e-7) rad (A-0.0256° for a vertical tool).
    """
    norms = np.linalg.norm(axes, axis=1)
    bad = ~(np.abs(norms - 1.0) <= AXIS_UNIT_TOLERANCE)
    if np.any(bad):
        i = int(np.argmax(bad))
        raise KinematicsError(f"tool axis {axes[i].tolist()} at {locate(i)} has length "
                              f"{norms[i]:.9g}, not 1 within {AXIS_UNIT_TOLERANCE:g}")
    return axes / norms[:, None]


def inverse(machine: Machine, points: np.ndarray, axes: np.ndarray,
            locate: Locator | None = None, previous: np.ndarray | None = None,
            with_undefined: bool = False):
    """Tool-tip points and unit axes (part frame) -> joint vectors (n, J).

    Of the two orientation solutions each point takes the one within limits that moves
    least from the point before (the first from `previous`, default home); continuous axes
    unwind (no 360° jumps); an undefined angle keeps its previous value. Raises
    KinematicsError naming the segment and point for unreachable or out-of-limit poses.
    With `with_undefined` also returns the (n, r) mask of angles that were free there.
    """
    locate = locate or (lambda i: f"point {i}")
    points = np.asarray(points, dtype=float)
    axes = unit_axes(np.asarray(axes, dtype=float), locate)
    start = machine.home_joints() if previous is None else np.asarray(previous, dtype=float)
    candidates = rotary_candidates(machine, axes, locate)
    rotary = choose_rotary(machine, candidates, start[3:], locate)
    joints = np.empty((len(points), 3 + len(machine.rotary)))
    joints[:, 3:] = rotary
    joints[:, :3] = table_transform(machine, joints, points) - head_offset(machine, joints)
    joints = _fit_linear_limits(machine, points, candidates, joints)
    check_linear_limits(machine, joints, locate)
    if with_undefined:
        return joints, np.isnan(candidates).all(axis=1)
    return joints


def _outside_linear(machine: Machine, joints: np.ndarray) -> np.ndarray:
    low = np.array([a.limits[0] for a in machine.linear]) - LIMIT_SLACK
    high = np.array([a.limits[1] for a in machine.linear]) + LIMIT_SLACK
    return ((joints[..., :3] < low) | (joints[..., :3] > high)).any(axis=-1)


def _fit_linear_limits(machine: Machine, points: np.ndarray, candidates: np.ndarray,
                       joints: np.ndarray) -> np.ndarray:
    """Poses whose chosen angles put X, Y or Z out of limits: take instead the other
    orientation solution, or another value of an angle that is free there (a tool axis
    along a rotary axis), whichever fits and turns least."""
    outside = _outside_linear(machine, joints)
    if not outside.any() or not machine.rotary:
        return joints
    joints = _hold_free_runs(machine, points, candidates, joints, outside)
    rows = np.flatnonzero(_outside_linear(machine, joints))
    if len(rows) == 0:
        return joints
    chosen = joints[rows, 3:]                                      # (m, r), unwound
    raw = candidates[rows]                                         # (m, branches, r)
    free = np.isnan(raw)
    options = [np.where(free, chosen[:, None, :], chosen[:, None, :] + _wrap_pi(raw - chosen[:, None, :]))]
    for k in range(raw.shape[2]):
        for step in FREE_ANGLE_STEPS:
            swept = options[0].copy()
            swept[..., k] = np.where(free[..., k], chosen[:, None, k] + step, swept[..., k])
            options.append(swept)
    options = np.concatenate(options, axis=1)                      # (m, o, r)
    m, o, r = options.shape
    trial = np.empty((m, o, 3 + r))
    trial[..., 3:] = options
    flat = trial.reshape(m * o, 3 + r)
    flat[:, :3] = positions_for(machine, np.repeat(points[rows], o, axis=0), flat)
    fits = ~_outside_linear(machine, trial)
    for k, axis in enumerate(machine.rotary):
        if axis.limits is not None:
            fits &= ((options[..., k] >= axis.limits[0] - LIMIT_SLACK)
                     & (options[..., k] <= axis.limits[1] + LIMIT_SLACK))
    cost = np.where(fits, np.abs(options - chosen[:, None, :]).sum(axis=2), np.inf)
    best = np.argmin(cost, axis=1)
    for run in _runs(rows):
        # one option for a run of consecutive refused poses when one fits them all: picked
        # pose by pose, neighbours could take turns either side (C +5°, -5°, +5°) and the
        # joints would jump within every move between them
        common = fits[run].all(axis=0)
        if common.any() and len(run) > 1:
            best[run] = int(np.argmin(np.where(common, cost[run].sum(axis=0, where=common[None, :]
                                                                    & fits[run]), np.inf)))
    found = np.isfinite(cost[np.arange(m), best])
    out = joints.copy()
    out[rows[found]] = trial[np.flatnonzero(found), best[found]]
    return out


def _hold_free_runs(machine: Machine, points: np.ndarray, candidates: np.ndarray,
                    joints: np.ndarray, outside: np.ndarray) -> np.ndarray:
    """Where an angle is free over a run of consecutive poses (the tool along that rotary
    axis, as a planar layer on an A/C table) and some of them are outside the linear travel,
    give the whole run the one value of that angle, turned least, that puts all of it inside:
    the angle then holds still while the tool moves instead of turning back and forth."""
    free = np.isnan(candidates).all(axis=1)                      # (n, r)
    out = joints.copy()
    for k, axis in enumerate(machine.rotary):
        indices = np.flatnonzero(free[:, k])
        for run in (indices[p] for p in _runs(indices)):
            if not outside[run].any():
                continue
            for step in sorted(FREE_ANGLE_STEPS, key=abs):
                trial = out[run].copy()
                trial[:, 3 + k] += step
                if axis.limits is not None and not (
                        (trial[:, 3 + k] >= axis.limits[0] - LIMIT_SLACK).all()
                        and (trial[:, 3 + k] <= axis.limits[1] + LIMIT_SLACK).all()):
                    continue
                trial[:, :3] = positions_for(machine, points[run], trial)
                if not _outside_linear(machine, trial).any():
                    out[run] = trial
                    break
    return out


def _runs(rows: np.ndarray) -> list[np.ndarray]:
    """Positions in `rows` (sorted point indices) grouped into runs of consecutive points."""
    breaks = np.flatnonzero(np.diff(rows) != 1) + 1
    return np.split(np.arange(len(rows)), breaks)


def _wrap_pi(delta: np.ndarray) -> np.ndarray:
    return (delta + np.pi) % (2.0 * np.pi) - np.pi


def positions_for(machine: Machine, points: np.ndarray, joints: np.ndarray) -> np.ndarray:
    """X, Y, Z that put the tip on part-frame `points` with the rotary angles in `joints`."""
    return table_transform(machine, joints, points) - head_offset(machine, joints)


def check_linear_limits(machine: Machine, joints: np.ndarray, locate: Locator) -> None:
    for k, axis in enumerate(machine.linear):
        low, high = axis.limits
        bad = (joints[:, k] < low - LIMIT_SLACK) | (joints[:, k] > high + LIMIT_SLACK)
        if np.any(bad):
            i = int(np.argmax(bad))
            raise KinematicsError(f"{axis.name} = {joints[i, k]:.4f} mm at {locate(i)} is outside "
                                  f"the limits [{low}, {high}] of machine {machine.name}")
