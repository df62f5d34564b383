"""Ball-end finishing: the swept volume, the stepover, the tool axes a face takes."""
from __future__ import annotations

import math

import numpy as np
import pytest

from freecad_conformal.paths.ball_finish import BallSweep, face_axes, scallop_stepover

UP = np.array([0.0, 0.0, 1.0])


def test_ball_sweep_holds_what_lies_within_the_radius_of_its_path():
    sweep = BallSweep(np.array([[0.0, 0, 0], [10.0, 0, 0], [10.0, 10.0, 0]]), 3.0)
    points = np.array([[5.0, 2.9, 0], [5.0, 3.1, 0], [-2.9, 0, 0], [-3.1, 0, 0],
                       [12.0, 12.0, 0], [13.1, 5.0, 0], [12.0, -2.0, 0]])
    # along the first leg, past its start, by the corner (a sphere about it), the second leg
    assert sweep.holds(points).tolist() == [True, False, True, False, True, False, True]


def test_stepover_leaves_the_cusp_asked_on_a_flat():
    step = scallop_stepover(3.0, 0.04)
    # two balls step apart meet 0.04 mm above the flat
    assert 3.0 - math.sqrt(9.0 - (step / 2) ** 2) == pytest.approx(0.04)


def _hemisphere(sign: float) -> np.ndarray:
    a = np.linspace(0, 2 * np.pi, 24, endpoint=False)
    e = np.linspace(0, np.pi / 2, 8)
    return np.array([(math.cos(x) * math.cos(y), math.sin(x) * math.cos(y), sign * math.sin(y))
                     for x in a for y in e])


def test_a_dome_takes_one_axis_and_a_sphere_none_from_below():
    dome = face_axes(_hemisphere(1.0), [UP], UP)
    assert len(dome) == 1 and (_hemisphere(1.0) @ dome[0] >= -1e-9).all()
    sphere = np.vstack([_hemisphere(1.0), _hemisphere(-1.0)])
    axes = face_axes(sphere, [UP], UP)
    assert 2 <= len(axes) <= 4 and all(float(a @ UP) >= -1e-9 for a in axes)
    # between them every normal has an axis within 90°, the ball's lower half on it
    assert (np.max([sphere @ a for a in axes], axis=0) >= -1e-9).all()
    # a quarter round (a fillet on a box's top edge) takes its mean normal, 45° up
    quarter = np.array([(-math.cos(t), 0.0, math.sin(t)) for t in np.linspace(0, np.pi / 2, 9)])
    (fillet,) = face_axes(quarter, [UP], UP)
    assert fillet == pytest.approx(np.array([-1.0, 0.0, 1.0]) / math.sqrt(2))
