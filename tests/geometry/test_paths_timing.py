"""The time model: trapezoids, jerk-limited corners, reachable junction speeds."""
from __future__ import annotations

import numpy as np
import pytest

from freecad_conformal.paths.timing import estimate_time, junction_speeds, move_times
from freecad_conformal.toolpath import ToolpathBuilder


def test_long_straight_move_is_length_over_speed_plus_ramps():
    # 100 mm at 50 mm/s, a = 1000: ramps of 1.25 mm each cost v/a = 0.05 s extra
    times = move_times(np.array([100.0]), np.array([50.0]), np.zeros(2), 1000.0)
    assert times[0] == pytest.approx(100 / 50 + 50 / 1000)


def test_short_move_is_a_triangle():
    times = move_times(np.array([1.0]), np.array([100.0]), np.zeros(2), 1000.0)
    assert times[0] == pytest.approx(2 * np.sqrt(1.0 / 1000.0))


def test_straight_on_keeps_speed_and_a_right_angle_is_jerk_limited():
    directions = np.array([[1.0, 0, 0], [1.0, 0, 0], [0.0, 1, 0]])
    junction = junction_speeds(directions, np.array([50.0, 50.0, 50.0]), jerk=10.0)
    assert junction[0] == 0 and junction[-1] == 0
    assert junction[1] == pytest.approx(50.0)
    assert junction[2] == pytest.approx(10.0 / (2 * np.sin(np.pi / 4)))


def test_estimate_time_of_a_square_lies_between_bounds():
    builder = ToolpathBuilder()
    square = [[10, 0, 0], [10, 10, 0], [0, 10, 0], [0, 0, 0]]
    builder.add_segment([[0, 0, 0]], kind="travel", feed=6000)
    builder.add_segment(square, kind="deposit", feed=3000, flow=0.08)
    tp = builder.build()
    seconds = estimate_time(tp, acceleration=1000.0, jerk=10.0)
    cruise = 40.0 / 50.0
    assert cruise < seconds < cruise + 4 * 2 * 50.0 / 1000.0
    slower = estimate_time(tp, acceleration=100.0, jerk=10.0)
    assert slower > seconds


def test_feeds_are_capped_by_the_machine():
    builder = ToolpathBuilder()
    builder.add_segment([[0, 0, 0], [100, 0, 0]], kind="deposit", feed=12000, flow=0.08)
    tp = builder.build()
    capped = estimate_time(tp, acceleration=1e9, max_feed=6000)
    assert capped == pytest.approx(1.0, rel=1e-6)
