"""Wrapped rotary axes and limited multi-turn axes: never the wrong way, never unbounded."""
from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest

from freecad_conformal.errors import KinematicsError, PostError
from freecad_conformal.post import samples
from freecad_conformal.post.machine import MACHINES_DIR, machine_from_dict
from freecad_conformal.post.program import post_toolpath
from freecad_conformal.post.verify import verify_program
from freecad_conformal.toolpath import ToolpathBuilder

TOL, ATOL_DEG = 0.01, 0.05


def shipped(name: str) -> dict:
    return json.loads((MACHINES_DIR / f"{name}.json").read_text())


def tilted_ring(turns: float, points: int = 50, radius: float = 8.0, tilt_deg: float = 30.0):
    t = np.linspace(0.0, turns * 2.0 * math.pi, points)
    tilt = math.radians(tilt_deg)
    ring = np.stack([radius * np.cos(t), radius * np.sin(t), np.full_like(t, 5.0)], axis=1)
    axes = np.stack([math.sin(tilt) * np.cos(t), math.sin(tilt) * np.sin(t),
                     np.full_like(t, math.cos(tilt))], axis=1)
    builder = ToolpathBuilder(part=f"{turns}-turn ring")
    builder.add_segment(ring, axes, kind="cure", feed=100.0)
    return builder.build()


def rotary_words(text: str, letter: str) -> list[float]:
    return [float(v) for v in re.findall(rf"^G[01].* {letter}(-?[\d.]+)", text, re.MULTILINE)]


def test_wrapped_axis_never_turns_half_a_turn_in_one_block():
    data = shipped("trunnion_ac")
    data["rotary_axes"][1]["wrap"] = True
    machine = machine_from_dict(data)
    toolpath = tilted_ring(0.6)
    result = post_toolpath(toolpath, machine)
    angles = rotary_words(result.text, "C")
    assert all(0.0 <= c < 360.0 for c in angles)
    steps = np.abs((np.diff(angles) + 180.0) % 360.0 - 180.0)
    assert steps.max() < 180.0 and abs(np.sum(np.diff(np.unwrap(np.radians(angles))))) > 3.7
    deviation = verify_program(result.text, machine, toolpath)
    assert deviation.position <= TOL * 1.05 and math.degrees(deviation.angle) <= ATOL_DEG * 1.05


def test_full_turn_on_a_wrapped_mandrel_moves_and_has_a_feed():
    data = shipped("rotary_mandrel")
    data["rotary_axes"][0]["wrap"] = True
    machine = machine_from_dict(data)
    toolpath = samples.mandrel_helix(turns=1.0, pitch=0.0)     # one closed ring
    result = post_toolpath(toolpath, machine)
    moves = [l for l in result.text.splitlines() if l.startswith("G1")]
    assert not any(re.search(r"F0(\s|$)", l) for l in moves)
    assert len([l for l in moves if " A" in l]) >= 4
    deviation = verify_program(result.text, machine, toolpath)
    assert deviation.position <= TOL * 1.05


DATA_MACHINES = __import__("pathlib").Path(__file__).parent / "data" / "machines"


def head_head(c_limits: list[float]):
    data = json.loads((DATA_MACHINES / "head_head_cb.json").read_text())
    data["rotary_axes"][0]["limits"] = c_limits
    return machine_from_dict(data, source="head_head_cb.json")


def test_limited_axis_fits_a_turn_and_a_half_by_a_whole_turn_offset():
    machine, toolpath = head_head([-360, 360]), tilted_ring(1.5, points=92)
    result = post_toolpath(toolpath, machine)
    c = np.array(rotary_words(result.text, "C"))
    assert c.min() >= -360 and c.max() <= 360 and c.max() - c.min() > 500
    assert np.abs(np.diff(c)).max() < 10.0                     # no whole-turn jump
    deviation = verify_program(result.text, machine, toolpath)
    assert deviation.position <= TOL * 1.05 and math.degrees(deviation.angle) <= ATOL_DEG * 1.05


def test_limited_axis_needing_more_travel_than_its_limits_is_refused_early():
    machine, toolpath = head_head([-360, 360]), tilted_ring(2.5, points=152)
    with pytest.raises(KinematicsError, match=r"axis C .* 900\.0° of travel .* allow 720°"):
        post_toolpath(toolpath, machine)


def test_limit_forcing_the_other_solution_mid_move_is_refused_not_split_forever():
    # 0.6 turn with C within ±100°: one branch leaves the limits mid-ring, the other is
    # 180° away; this used to split the move until 13 GB were gone
    machine, toolpath = head_head([-100, 100]), tilted_ring(0.6, points=38)
    with pytest.raises(PostError, match=r"joints jump .*C limits \[-100, 100\]"):
        post_toolpath(toolpath, machine)
