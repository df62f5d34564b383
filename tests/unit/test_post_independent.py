"""Every dialect read back by readers written elsewhere, and replayed through kinematics.

LinuxCNC output goes through LinuxCNC's own interpreter (test_post_dialects); here the
Marlin, RepRapFirmware and grblHAL programs are read by `gcodeparser` (a G-code library
from PyPI) for the joint targets and by Printrun's `gcoder` (Pronterface's reader) for the
extrusion, then every shipped machine × dialect is replayed through forward kinematics.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from freecad_conformal.post import samples
from freecad_conformal.post.machine import load_machine
from freecad_conformal.post.program import post_toolpath
from freecad_conformal.post.verify import verify_program

gcodeparser = pytest.importorskip("gcodeparser")

CASES = [
    ("head_a_table_c", "grblhal", samples.tilted_ring),
    ("rotary_mandrel", "marlin", lambda: samples.mandrel_helix(turns=3)),
    ("three_axis", "reprap", samples.flat_square),
    ("three_axis", "marlin", samples.flat_square),
    ("trunnion_ac", "reprap", samples.tilted_ring),
    ("trunnion_ac", "grblhal", lambda: samples.dome_spiral(600, turns=3, segments=4)),
]


def targets_by_gcodeparser(text: str, names: tuple[str, ...]) -> np.ndarray:
    current: dict[str, float] = {}
    rows = []
    parsed = list(gcodeparser.parse_gcode_lines(text))
    machine_coordinates = {line.line_index for line in parsed if line.command == ("G", 53)}
    for line in parsed:
        if line.command not in (("G", 0), ("G", 1)) or line.line_index in machine_coordinates:
            continue                   # G53 G0: to the tool-change height, not a block
        for name in names:
            if name in line.params:
                current[name] = float(line.params[name])
        rows.append([current.get(name, math.nan) for name in names])
    return np.array(rows)


@pytest.mark.parametrize("machine_name, dialect, make", CASES)
def test_gcodeparser_reads_the_joints_we_meant(machine_name, dialect, make):
    machine = load_machine(machine_name)
    result = post_toolpath(make(), machine, dialect)
    read = targets_by_gcodeparser(result.text, result.names)
    assert read.shape == result.values.shape
    assert np.abs(read - result.values).max() <= 5.1e-5


@pytest.mark.parametrize("dialect", ["marlin", "reprap"])
@pytest.mark.parametrize("relative", [True, False])
def test_printrun_counts_the_filament_the_header_claims(dialect, relative):
    gcoder = pytest.importorskip("printrun.gcoder")
    machine, toolpath = load_machine("three_axis"), samples.flat_square()
    result = post_toolpath(toolpath, machine, dialect, relative_e=relative)
    filament = gcoder.GCode(result.text.splitlines()).filament_length
    area = math.pi * machine.filament_diameter ** 2 / 4.0
    volume = toolpath.summary().material_volume
    assert filament * area == pytest.approx(volume, rel=1e-4)


@pytest.mark.parametrize("machine_name", ["trunnion_ac", "head_a_table_c", "rotary_mandrel",
                                          "three_axis"])
@pytest.mark.parametrize("dialect", ["linuxcnc", "grblhal", "marlin", "reprap"])
def test_every_dialect_replays_within_tolerance(machine_name, dialect):
    machine = load_machine(machine_name)
    toolpath = {"rotary_mandrel": lambda: samples.mandrel_helix(turns=2),
                "three_axis": samples.flat_square}.get(machine_name, samples.tilted_ring)()
    result = post_toolpath(toolpath, machine, dialect)
    deviation = verify_program(result.text, machine, toolpath)
    assert deviation.position <= 0.01 and math.degrees(deviation.angle) <= 0.05
