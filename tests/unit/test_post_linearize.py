"""Linearisation: tolerance met, block count near the minimum, helix as one block."""
from __future__ import annotations

import math

import numpy as np
import pytest

from freecad_conformal.post import samples
from freecad_conformal.post.kinematics import forward, inverse
from freecad_conformal.post.linearize import linearize, slerp
from freecad_conformal.post.machine import load_machine
from freecad_conformal.toolpath import ToolpathBuilder

TOL = 0.01
ATOL = math.radians(0.05)


def dense_deviation(machine, blocks, start, end, axis_start, axis_end, samples_per_block=50):
    """Largest tip distance from the designed line and axis error, sampled densely."""
    s = np.linspace(0, 1, samples_per_block)
    worst_position, worst_angle = 0.0, 0.0
    chord = end - start
    for q0, q1 in zip(blocks.joints[:-1], blocks.joints[1:]):
        tip, axis = forward(machine, q0 + s[:, None] * (q1 - q0))
        t = np.clip((tip - start) @ chord / (chord @ chord), 0, 1)
        worst_position = max(worst_position, np.linalg.norm(tip - (start + t[:, None] * chord), axis=1).max())
        designed = slerp(np.repeat([axis_start], len(s), 0), np.repeat([axis_end], len(s), 0), t)
        worst_angle = max(worst_angle, np.arccos(np.clip((axis * designed).sum(1), -1, 1)).max())
    return worst_position, worst_angle


def one_move(start, end, axis_start, axis_end):
    builder = ToolpathBuilder()
    builder.add_segment([start, end], [axis_start, axis_end], kind="cure", feed=100)
    return builder.build()


@pytest.mark.parametrize("name", ["trunnion_ac", "head_a_table_c"])
def test_part_linear_move_within_tolerance_with_near_minimal_blocks(name):
    machine = load_machine(name)
    start, end = np.array([5.0, 0, 10]), np.array([40.0, 15, 12])
    a0, a1 = np.array([0, 0.3, 1.0]), np.array([0.6, 0, 1.0])
    a0, a1 = a0 / np.linalg.norm(a0), a1 / np.linalg.norm(a1)
    blocks = linearize(one_move(start, end, a0, a1), machine, TOL, ATOL)
    position, angle = dense_deviation(machine, blocks, start, end, a0, a1)
    assert position <= TOL * 1.05 and angle <= ATOL * 1.05
    # the fewest equal parts that meet the tolerance, found by brute force
    fewest = None
    for k in range(1, 400):
        s = np.linspace(0, 1, k + 1)
        pts = start + s[:, None] * (end - start)
        axes = slerp(np.repeat([a0], k + 1, 0), np.repeat([a1], k + 1, 0), s)
        joints = inverse(machine, pts, axes)
        trial = type(blocks)(joints, np.zeros(k + 1, int), np.zeros(k + 1), np.zeros(k + 1, int))
        p, a = dense_deviation(machine, trial, start, end, a0, a1)
        if p <= TOL and a <= ATOL:
            fewest = k
            break
    moves = len(blocks.joints) - 1
    assert fewest is not None and fewest <= moves <= math.ceil(1.2 * fewest) + 1


def test_three_axis_collinear_points_merge():
    machine = load_machine("three_axis")
    builder = ToolpathBuilder()
    builder.add_segment(np.linspace([10, 10, 1], [60, 10, 1], 51), kind="deposit", feed=600, flow=0.1)
    builder.add_segment([[60, 10, 1], [60, 40, 1]], kind="deposit", feed=900, flow=0.1)
    blocks = linearize(builder.build(), machine)
    assert len(blocks.joints) == 3     # start, one block per straight run
    assert blocks.tip_length.tolist() == pytest.approx([0.0, 50.0, 30.0])


def test_gentle_arc_is_not_merged_beyond_tolerance():
    machine = load_machine("three_axis")
    t = np.linspace(0, 0.5, 2000)
    arc = np.stack([100 + 1000 * np.sin(t) / 10, 100 + 100 * (1 - np.cos(t)), np.ones_like(t)], 1)
    builder = ToolpathBuilder()
    builder.add_segment(arc, kind="deposit", feed=600)
    blocks = linearize(builder.build(), machine)
    kept = blocks.point
    assert len(blocks.joints) < len(arc)
    for a, b in zip(kept[:-1], kept[1:]):
        chord = arc[b] - arc[a]
        inner = arc[a:b + 1] - arc[a]
        off = np.linalg.norm(inner - np.outer(inner @ chord / (chord @ chord), chord), axis=1)
        assert off.max() <= 0.01 * TOL + 1e-12


def test_helix_joint_linear_is_one_block():
    machine = load_machine("rotary_mandrel")
    tp = samples.mandrel_helix(turns=10)
    blocks = linearize(tp, machine)
    assert len(blocks.joints) == 3                     # start, travel, the whole helix
    assert math.degrees(abs(blocks.joints[-1, 3] - blocks.joints[1, 3])) == pytest.approx(3600.0)
    # the designed length is the sum of the planner's chords: within 5e-4 of the arc at 0.01 mm
    assert blocks.tip_length[-1] == pytest.approx(math.hypot(2 * math.pi * 20, 2) * 10, rel=5e-4)


def test_leaving_the_pole_turns_c_first():
    machine = load_machine("trunnion_ac")
    builder = ToolpathBuilder()
    builder.add_segment([[20, 0, 10], [20, 0, 10], [50, 0, 10]], [[0, 1, 1], [0, 0, 1], [1, 0, 1]],
                        kind="cure", feed=100)
    tp = builder.build()
    blocks = linearize(tp, machine)
    a, c = blocks.joints[:, 3], blocks.joints[:, 4]
    turning = np.flatnonzero(np.abs(np.diff(c)) > 1e-12)
    assert np.all(np.abs(a[turning]) < 1e-9) and np.all(np.abs(a[turning + 1]) < 1e-9)
    tip, _ = forward(machine, blocks.joints[turning + 1])
    assert np.abs(tip - [20, 0, 10]).max() < 1e-9


@pytest.mark.parametrize("name", ["trunnion_ac", "head_a_table_c"])
def test_moves_that_turn_no_rotary_joint_follow_their_chord(name):
    """The deviation check skips moves whose rotary joints and designed axis stay: their
    tip follows the chord. Those read 0, the others as the full forward check reads them,
    and the skipped moves' full check is indeed within rounding of 0."""
    from freecad_conformal.post import linearize as module

    machine = load_machine(name)
    rng = np.random.default_rng(5)
    points = rng.uniform(-20, 20, size=(9, 3))
    axes = np.repeat([[0.0, 0.0, 1.0]], 9, axis=0)
    axes[5:] = [0.0, math.sin(0.3), math.cos(0.3)]      # one reorientation: into row 5
    joints, _ = inverse(machine, points, axes, lambda i: f"row {i}", with_undefined=True)
    joints = joints.copy()
    ratio = module._deviation_ratio(machine, points, axes, joints, TOL, ATOL)
    turning = np.any(joints[1:, 3:] != joints[:-1, 3:], axis=1) | np.any(axes[1:] != axes[:-1], axis=1)
    assert turning[4] and not turning[:4].any() and not turning[5:].any()
    assert np.all(ratio[~turning] == 0.0) and ratio[4] > 0.0
    # The full check, every move: what the skipped moves would have read.
    full = np.zeros(len(points) - 1)
    chord = points[1:] - points[:-1]
    for s in module.CHECK_PARAMETERS:
        tip, axis = forward(machine, joints[:-1] + s * (joints[1:] - joints[:-1]))
        t = np.clip(np.einsum("ij,ij->i", tip - points[:-1], chord)
                    / np.einsum("ij,ij->i", chord, chord), 0.0, 1.0)
        position = np.linalg.norm(tip - (points[:-1] + t[:, None] * chord), axis=1)
        designed = slerp(axes[:-1], axes[1:], t)
        angle = np.arccos(np.clip(np.einsum("ij,ij->i", axis, designed), -1.0, 1.0))
        full = np.maximum(full, np.maximum(position / TOL, angle / ATOL))
    full /= module.CHECK_MARGIN
    assert np.all(full[~turning] < 1e-3)
    assert ratio[4] == pytest.approx(full[4], rel=1e-9)
