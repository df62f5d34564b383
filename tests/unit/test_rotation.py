"""Rodrigues rotations that bring a build direction to the machine's +Z."""
from __future__ import annotations

import math

import numpy as np
import pytest

from freecad_conformal.errors import PlanError
from freecad_conformal.geometry.rotation import rodrigues_matrix, rotate_points, rotation_to


def test_matrix_is_a_rotation_and_turns_x_to_y_about_z():
    R = rodrigues_matrix([0, 0, 2], math.pi / 2)
    np.testing.assert_allclose(R @ [1, 0, 0], [0, 1, 0], atol=1e-15)
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-15)
    assert np.linalg.det(R) == pytest.approx(1.0)


@pytest.mark.parametrize("direction, axis, degrees", [
    ((0, 1, 0), (1, 0, 0), 90.0),      # METHODS 3 hinge: 90° about X
    ((0, 0, -1), (0, 1, 0), 180.0),    # METHODS 3 hinge: 180° about Y
    ((1, 0, 0), (0, -1, 0), 90.0),
    ((-1, 0, 0), (0, 1, 0), 90.0),
    ((0, 0, 1), (0, 0, 1), 0.0),
])
def test_rotation_to_build_axis(direction, axis, degrees):
    found_axis, angle = rotation_to(direction)
    np.testing.assert_allclose(found_axis, axis, atol=1e-12)
    assert math.degrees(angle) == pytest.approx(degrees)
    np.testing.assert_allclose(rodrigues_matrix(found_axis, angle) @ np.array(direction, float),
                               [0, 0, 1], atol=1e-12)


def test_oblique_direction_reaches_z_and_points_keep_distances():
    d = np.array([1.0, 2.0, -0.5])
    axis, angle = rotation_to(d)
    np.testing.assert_allclose(rodrigues_matrix(axis, angle) @ (d / np.linalg.norm(d)), [0, 0, 1],
                               atol=1e-12)
    points = np.array([[1.0, 2.0, 3.0], [4.0, -1.0, 0.5]])
    moved = rotate_points(points, axis, angle, centre=[1, 1, 1])
    assert np.linalg.norm(moved[0] - moved[1]) == pytest.approx(np.linalg.norm(points[0] - points[1]))


def test_zero_direction_is_refused():
    with pytest.raises(PlanError, match="zero vector"):
        rotation_to([0, 0, 0])
