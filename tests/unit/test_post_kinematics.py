"""Kinematics: the expected angles, FK/IK round trips, unwinding, poles, limits, schema."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from freecad_conformal.errors import KinematicsError
from freecad_conformal.post.kinematics import forward, inverse
from freecad_conformal.post.machine import load_machine, machine_from_dict, machine_names


def unit(v):
    v = np.atleast_2d(np.asarray(v, dtype=float))
    return v / np.linalg.norm(v, axis=1)[:, None]


def test_shipped_machines():
    assert {"trunnion_ac", "head_a_table_c", "rotary_mandrel", "three_axis"} <= set(machine_names())


def test_table_table_expected_angles():
    machine = load_machine("trunnion_ac")
    joints = inverse(machine, np.zeros((2, 3)), unit([[1, 1, 1], [0, 0, 1]]))
    a, c = np.degrees(joints[0, 3:])
    assert abs(a) == pytest.approx(54.7356, abs=1e-4)
    assert (a, c) == pytest.approx((54.7356, 45.0), abs=1e-4) or \
        (a, c) == pytest.approx((-54.7356, -135.0), abs=1e-4)
    assert joints[1, 3] == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("name", ["trunnion_ac", "head_a_table_c"])
def test_forward_inverts_inverse_for_random_poses(name):
    machine = load_machine(name)
    rng = np.random.default_rng(7)
    axes = unit(rng.normal(size=(300, 3)) * [1, 1, 0.3] + [0, 0, 1.0])
    axes = axes[axes[:, 2] > 0.2]
    points = rng.uniform(-20, 20, size=(len(axes), 3))
    joints = inverse(machine, points, axes)
    tip, axis = forward(machine, joints)
    assert np.abs(tip - points).max() < 1e-9 and np.abs(axis - axes).max() < 1e-9


def test_mandrel_and_three_axis_round_trip_and_reach():
    mandrel = load_machine("rotary_mandrel")
    t = np.linspace(0, 7, 50)
    axes = np.stack([0 * t, np.sin(t), np.cos(t)], axis=1)
    joints = inverse(mandrel, axes * 20 + [3, 0, 0], axes)
    assert np.allclose(np.diff(joints[:, 3]), np.diff(-t), atol=1e-12) or \
        np.allclose(np.diff(joints[:, 3]), np.diff(t), atol=1e-12)
    with pytest.raises(KinematicsError, match="point 1 is not reachable"):
        inverse(mandrel, np.zeros((2, 3)) + [0, 0, 20], unit([[0, 0, 1], [1, 0, 1]]))
    with pytest.raises(KinematicsError, match="has no rotary axis"):
        inverse(load_machine("three_axis"), [[10, 10, 10]], unit([[0, 1, 1]]))


def test_continuous_c_unwinds_and_pole_keeps_previous_c():
    machine = load_machine("trunnion_ac")
    t = np.linspace(0, 6 * math.pi, 200)
    axes = unit(np.stack([0.3 * np.cos(t), 0.3 * np.sin(t), np.ones_like(t)], axis=1))
    c = np.degrees(inverse(machine, np.zeros((200, 3)), axes)[:, 4])
    assert np.abs(np.diff(c)).max() < 10.0 and abs(c[-1] - c[0]) == pytest.approx(1080.0, abs=1e-6)
    sweep = np.linspace(-0.5, 0.5, 11)         # through the pole: A changes sign, C stays
    joints = inverse(machine, np.zeros((11, 3)), np.stack([np.sin(sweep), 0 * sweep, np.cos(sweep)], 1))
    assert np.ptp(joints[:, 4]) == pytest.approx(0.0, abs=1e-12)
    assert np.allclose(np.abs(joints[:, 3]), np.abs(sweep))
    back = inverse(machine, np.zeros((3, 3)), unit([[0, 1, 1], [0, 0, 1], [0, 0, 1]]))
    assert back[1, 4] == back[0, 4] == back[2, 4]


def test_out_of_limits_names_segment_and_point():
    machine = load_machine("head_a_table_c")           # A within ±100°
    axes = unit([[0, 0, 1], [0, 1, 0.2], [0, 1, -0.5]])
    with pytest.raises(KinematicsError, match=r"outside the limits.*A = "):
        inverse(machine, np.zeros((3, 3)), axes, locate=lambda i: f"segment 4 point {i}")
    with pytest.raises(KinematicsError, match="segment 4 point 2"):
        inverse(machine, np.zeros((3, 3)), axes, locate=lambda i: f"segment 4 point {i}")
    with pytest.raises(KinematicsError, match="X = 500.0000 mm at point 0"):
        inverse(machine, [[500, 0, 0]], unit([[0, 0, 1]]))


def test_schema_errors(tmp_path):
    good = json.loads(open(load_machine("trunnion_ac").source).read())
    for change, message in [
        (lambda d: d.pop("dialect"), "missing key"),
        (lambda d: d.update(colour="red"), "unknown key"),
        (lambda d: d["rotary_axes"][0].update(limits=[10, -10]), "low < high"),
        (lambda d: d["rotary_axes"][1].update(direction=[0, 0, 0]), "zero vector"),
        (lambda d: d["rotary_axes"][0].update(wrap=True), "wrap needs a continuous"),
        (lambda d: d["linear_axes"].pop("Y"), "linear_axes.Y is missing"),
    ]:
        data = json.loads(json.dumps(good))
        change(data)
        with pytest.raises(KinematicsError, match=message):
            machine_from_dict(data, "test.json")
    with pytest.raises(KinematicsError, match="unknown machine 'no_such'"):
        load_machine("no_such")
    with pytest.raises(KinematicsError, match="does not exist"):
        load_machine(tmp_path / "gone.json")


@pytest.mark.parametrize("name", ["trunnion_ac", "head_a_table_c", "rotary_mandrel"])
def test_runs_of_one_axis_are_solved_as_each_point(name):
    """Solved once per run of equal axes, the candidates are those of each point, bit for
    bit, whatever the machine (axes it reaches: its own, from random angles)."""
    from freecad_conformal.post import kinematics

    machine = load_machine(name)
    rng = np.random.default_rng(3)
    joints = np.zeros((6, 3 + len(machine.rotary)))
    joints[:, 3:] = rng.uniform(-0.6, 0.6, size=(6, len(machine.rotary)))
    _, base = forward(machine, joints)
    axes = np.repeat(base, [1, 5, 2, 9, 1, 3], axis=0)
    axes[-1] = axes[0]                  # a run that comes back
    locate = lambda i: f"point {i}"     # noqa: E731
    expected = kinematics._rotary_candidates(machine, axes, locate)
    found = kinematics.rotary_candidates(machine, axes, locate)
    assert found.shape == expected.shape == (len(axes), *expected.shape[1:])
    assert np.array_equal(found, expected, equal_nan=True)


def test_an_unreachable_axis_in_a_run_is_named_by_its_own_point():
    machine = load_machine("three_axis")
    axes = np.repeat(unit([[0, 0, 1], [0, 0, 1], [1, 0, 1]]), [4, 3, 2], axis=0)
    with pytest.raises(KinematicsError, match="point 7"):
        inverse(machine, np.zeros((len(axes), 3)), axes)
