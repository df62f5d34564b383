"""Curing model (METHODS section 1) against hand-computed values."""
from __future__ import annotations

import math

import numpy as np
import pytest

from freecad_conformal.errors import ProcessError
from freecad_conformal.process.curing import (
    LineCuring, cure_depth, depth_for_line_width, exposure_for_depth, line_exposure, line_width,
    minimum_line_width)


def test_cure_depth_working_curve():
    # E = Ec·e² -> Cd = Dp·2
    assert cure_depth(10 * math.e ** 2, dp=0.1, ec=10) == pytest.approx(0.2)
    # E = 100, Ec = 10, Dp = 0.15: 0.15·ln 10 = 0.345388
    assert cure_depth(100, dp=0.15, ec=10) == pytest.approx(0.345388, abs=1e-6)
    assert cure_depth(10, dp=0.1, ec=10) == 0.0   # at Ec nothing cures
    assert cure_depth(5, dp=0.1, ec=10) == 0.0
    assert exposure_for_depth(0.2, dp=0.1, ec=10) == pytest.approx(10 * math.e ** 2)


def test_line_width():
    assert line_width(0.2, spot_diameter=1.0, dp=0.1) == pytest.approx(1.0)        # sqrt(1)
    assert line_width(0.05, spot_diameter=1.57, dp=0.1) == pytest.approx(0.785)    # 1.57·0.5
    assert line_width(0.0, spot_diameter=1.57, dp=0.1) == 0.0
    assert depth_for_line_width(0.785, 1.57, 0.1) == pytest.approx(0.05)


def test_exposure_from_power_spot_and_speed():
    # 0.1 W, B = 2 mm (W0 = 1 mm), 1 mm/s = 60 mm/min:
    # Gaussian peak sqrt(2/π)·0.1/(1·1) = 0.0797885 J/mm² = 7978.85 mJ/cm²
    assert line_exposure(0.1, 2.0, 60.0) == pytest.approx(7978.85, abs=0.01)
    # flat top: 4·0.1/(π·2·1) = 0.0636620 J/mm² = 6366.20 mJ/cm²
    assert line_exposure(0.1, 2.0, 60.0, "top_hat") == pytest.approx(6366.20, abs=0.01)
    # twice the speed, half the exposure
    assert line_exposure(0.1, 2.0, 120.0) == pytest.approx(7978.85 / 2, abs=0.01)


def test_width_versus_feed_and_limits():
    model = LineCuring(power=0.1, spot_diameter=2.0, dp=0.1, ec=10.0)
    # nothing cures once E = Ec: v = 7978.85/10 mm/s = 797.885 mm/s = 47873.1 mm/min
    assert model.max_feed() == pytest.approx(47873.1, abs=0.1)
    assert model.width(model.max_feed() * 1.01) == 0.0
    # a line as wide as the spot needs Cd = 2·Dp, E = Ec·e²: v = 797.885/e² mm/s
    feed = model.feed_for_width(2.0)
    assert feed == pytest.approx(797.885 / math.e ** 2 * 60, rel=1e-5)
    assert model.width(feed) == pytest.approx(2.0)
    widths = model.widths(np.array([feed / 4, feed / 2, feed, 2 * feed]))
    assert np.all(np.diff(widths) < 0)   # slower motion, wider line


def test_minimum_line_width():
    # the narrowest line that still cures 0.05 mm deep with a 0.3 mm spot, Dp 0.1: 0.3·0.5
    assert minimum_line_width(0.3, dp=0.1, min_depth=0.05) == pytest.approx(0.15)


@pytest.mark.parametrize("call", [
    lambda: cure_depth(10, dp=0, ec=10),
    lambda: cure_depth(-1, dp=0.1, ec=10),
    lambda: line_width(0.1, spot_diameter=-1, dp=0.1),
    lambda: line_exposure(0.1, 2.0, 0.0),
    lambda: line_exposure(0.1, 2.0, 60.0, "square"),
])
def test_bad_inputs_raise_process_error(call):
    with pytest.raises(ProcessError):
        call()
