"""Decomposition acceptance on parametric parts (METHODS sections 3 and 4)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from freecad_conformal.geometry import samples
from freecad_conformal.planning.decompose import decompose


def directions(plan):
    return [tuple(np.round(s.build_direction, 6) + 0.0) for s in plan.ordered()]


def test_l_block_splits_once_and_builds_the_arm_horizontally():
    plan = decompose(samples.l_block())
    assert len(plan.subparts) == 2
    assert directions(plan) == [(0, 0, 1), (1, 0, 0)]
    first, second = plan.ordered()
    assert second.parent == first.index
    assert first.volume == pytest.approx(10 * 20 * 40)
    assert second.volume == pytest.approx(30 * 20 * 10)
    assert plan.support_area == pytest.approx(0.0, abs=1e-6)
    assert math.degrees(second.rotation_angle) == pytest.approx(90.0)
    np.testing.assert_allclose(second.rotation_axis, [0, -1, 0], atol=1e-12)


def test_t_builds_the_stem_then_arms_in_plus_and_minus_x():
    plan = decompose(samples.t_block())
    assert len(plan.subparts) == 3
    assert directions(plan)[0] == (0, 0, 1)
    assert sorted(directions(plan)[1:]) == [(-1, 0, 0), (1, 0, 0)]
    root = plan.ordered()[0]
    assert all(s.parent == root.index for s in plan.ordered()[1:])
    assert sum(s.volume for s in plan.subparts) == pytest.approx(samples.t_block().Volume)
    assert plan.support_area == pytest.approx(0.0, abs=1e-6)
