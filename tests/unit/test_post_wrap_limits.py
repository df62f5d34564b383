"""Wrapped rotary axes and limited multi-turn axes: never the wrong way, never unbounded."""
from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest

from freecad_conformal.errors import KinematicsError
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
