"""What a machine shop needs beyond the kinematics: unit axes, sane machine files, start
and end code, tool lengths, extrusion control for every dialect."""
from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest

from freecad_conformal.errors import KinematicsError
from freecad_conformal.post import samples
from freecad_conformal.post.kinematics import inverse
from freecad_conformal.post.machine import MACHINES_DIR, load_machine, machine_from_dict


def shipped(name: str) -> dict:
    return json.loads((MACHINES_DIR / f"{name}.json").read_text())


def test_nearly_unit_tool_axis_is_normalised_not_tilted():
    machine = load_machine("trunnion_ac")
    joints = inverse(machine, np.array([[1.0, 2.0, 3.0]]), np.array([[0.0, 0.0, 0.9999999]]))
    assert abs(math.degrees(joints[0, 3])) < 1e-9


def test_tool_axis_far_from_unit_is_refused():
    machine = load_machine("trunnion_ac")
    with pytest.raises(KinematicsError, match=r"length 0\.99, not 1 within 1e-06"):
        inverse(machine, np.array([[1.0, 2.0, 3.0]]), np.array([[0.0, 0.0, 0.99]]))


@pytest.mark.parametrize("value", [0, -1.75])
def test_filament_diameter_must_be_positive(value):
    data = shipped("rotary_mandrel")
    data["filament_diameter"] = value
    with pytest.raises(KinematicsError, match=f"filament_diameter = {value} must be > 0"):
        machine_from_dict(data)
