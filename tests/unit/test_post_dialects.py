"""Dialects: golden files per dialect from mock toolpaths, dialect rules, LinuxCNC via rs274.

Regenerate the golden files after an intended change with CONFORMAL_UPDATE_GOLDEN=1.
"""
from __future__ import annotations

import dataclasses
import os
import re
from pathlib import Path

import numpy as np
import pytest

from freecad_conformal.errors import PostError
from freecad_conformal.post import samples
from freecad_conformal.post.machine import load_machine
from freecad_conformal.post.program import post_toolpath
from freecad_conformal.post.rs274 import canonical_moves, rs274_path

GOLDEN = Path(__file__).parent / "golden"

CASES = [
    ("trunnion_ac", "linuxcnc", samples.tilted_ring),
    ("head_a_table_c", "grblhal", samples.tilted_ring),
    ("rotary_mandrel", "marlin", lambda: samples.mandrel_helix(turns=3)),
    ("three_axis", "reprap", samples.flat_square),
    ("three_axis", "marlin", samples.flat_square),
    ("head_a_table_c", "linuxcnc", samples.tilted_ring),
]


def check_with_rs274(result, tmp_path: Path) -> None:
    """LinuxCNC's interpreter must accept the program and move to exactly our joints."""
    if rs274_path() is None:
        pytest.skip("rs274 (Debian package linuxcnc-uspace) is not installed")
    program = tmp_path / "program.ngc"
    program.write_text(result.text)
    kinds, values = canonical_moves(program)
    # G53 moves (to the tool-change height, machine coordinates) are not blocks of ours
    moving = [line for line in result.text.splitlines()
              if re.match(r"(G9[34] )?G[01] |G53 G0 ", line)]
    assert len(kinds) == len(moving)
    ours = [not line.startswith("G53") for line in moving]
    kinds = [kind for kind, keep in zip(kinds, ours) if keep]
    values = values[np.array(ours, dtype=bool)]
    assert len(kinds) == len(result.values)
    columns = {"X": 0, "Y": 1, "Z": 2, "A": 3, "B": 4, "C": 5}
    intended = result.values
    for k, name in enumerate(result.names):
        assert np.abs(values[:, columns[name]] - intended[:, k]).max() <= 5.1e-5, name
    assert kinds == ["traverse" if rapid else "feed" for rapid in result.rapid]


@pytest.mark.parametrize("machine_name, dialect, make", CASES)
def test_golden(machine_name, dialect, make, tmp_path):
    machine = load_machine(machine_name)
    result = post_toolpath(make(), machine, dialect)
    golden = GOLDEN / f"{machine_name}.{dialect}.gcode"
    if os.environ.get("CONFORMAL_UPDATE_GOLDEN") == "1":
        golden.write_text(result.text)
    assert result.text == golden.read_text(), f"{golden.name} differs (see module docstring)"
    if dialect == "linuxcnc":
        check_with_rs274(result, tmp_path)


def test_dialect_rules():
    ring = samples.tilted_ring()
    linuxcnc = post_toolpath(ring, load_machine("trunnion_ac"), "linuxcnc").text
    assert "G43.4" not in linuxcnc and "G93 G1" in linuxcnc and "G94" in linuxcnc
    assert all(" F" in line for line in linuxcnc.splitlines() if line.startswith("G93"))
    marlin = post_toolpath(samples.mandrel_helix(turns=1), load_machine("rotary_mandrel"), "marlin").text
    assert marlin.splitlines()[8:11] == ["G21", "G90", "M83"] and "G93" not in marlin
    absolute = post_toolpath(samples.flat_square(), load_machine("three_axis"), "marlin",
                             relative_e=False).text
    e_values = [float(v) for v in re.findall(r" E([\d.]+)", absolute)]
    assert "M82" in absolute and e_values == sorted(e_values)
    fan_machine = dataclasses.replace(load_machine("trunnion_ac"), light_control="fan")
    fan = post_toolpath(ring, fan_machine, "marlin").text
    assert "M106 S191" in fan and "M107" in fan
    reprap = post_toolpath(ring, load_machine("trunnion_ac"), "reprap").text
    assert "M3 S75" in reprap and "G4 P500" in reprap and "; part: tilted ring" in reprap


def test_marlin_feed_gives_tip_speed_on_helix():
    machine = load_machine("rotary_mandrel")
    result = post_toolpath(samples.mandrel_helix(turns=2), machine, "marlin")
    line = [l for l in result.text.splitlines() if l.startswith("G1") and " A" in l][-1]
    feed = float(re.search(r" F([\d.]+)", line).group(1))
    axial = 4.0                                   # 2 turns at 2 mm pitch: F applies to X
    tip_length = result.blocks.tip_length[-1]
    assert feed * tip_length / axial == pytest.approx(2000.0, rel=1e-3)   # minutes agree


def test_unknown_dialect():
    with pytest.raises(PostError, match="unknown G-code dialect 'fanuc'.*linuxcnc"):
        post_toolpath(samples.flat_square(), load_machine("three_axis"), "fanuc")


def test_the_header_says_the_callers_time():
    """A plan's summary estimates its time with jerk-limited corners and the machine's feed
    limits; its program's header said the toolpath's own trapezoid estimate (the elbow:
    0:30:05 in the G-code, 0:32:59 in the summary). Given, the caller's time is written."""
    machine = load_machine("trunnion_ac")
    own = post_toolpath(samples.tilted_ring(), machine, "linuxcnc")
    given = post_toolpath(samples.tilted_ring(), machine, "linuxcnc", time_s=1234.5)
    assert given.time_s == 1234.5 != own.time_s
    assert "(estimated time: 0:20:34 [1234.5 s])" in given.text.splitlines()[:8]
    def rest(text: str) -> list[str]:
        return [line for line in text.splitlines() if "estimated time" not in line]

    assert rest(given.text) == rest(own.text)
    for bad in (float("nan"), -1.0, float("inf")):
        with pytest.raises(PostError, match="estimated run time .* got"):
            post_toolpath(samples.tilted_ring(), machine, "linuxcnc", time_s=bad)
