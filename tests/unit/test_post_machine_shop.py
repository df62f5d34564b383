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


def test_only_the_mandrel_has_no_platform_and_the_key_must_be_true_or_false():
    assert {name: load_machine(name).platform for name in ("rotary_mandrel", "trunnion_ac",
                                                            "three_axis", "head_a_table_c")} \
        == {"rotary_mandrel": False, "trunnion_ac": True, "three_axis": True,
            "head_a_table_c": True}
    data = shipped("rotary_mandrel")
    data["platform"] = 0
    with pytest.raises(KinematicsError, match="platform"):
        machine_from_dict(data)


@pytest.mark.parametrize("value", [0, -1.75])
def test_filament_diameter_must_be_positive(value):
    data = shipped("rotary_mandrel")
    data["filament_diameter"] = value
    with pytest.raises(KinematicsError, match=f"filament_diameter = {value} must be > 0"):
        machine_from_dict(data)


def moves_and_codes(text: str) -> list[str]:
    return [line for line in text.splitlines() if line and line[0] not in "(;"]


def test_marlin_program_heats_and_homes_before_the_first_extrusion():
    from freecad_conformal.post.program import post_toolpath
    from freecad_conformal.post.verify import verify_program
    machine, toolpath = load_machine("three_axis"), samples.flat_square()
    text = post_toolpath(toolpath, machine, "marlin").text
    lines = moves_and_codes(text)
    first_e = next(i for i, line in enumerate(lines) if " E" in line)
    order = [lines.index(c) for c in ("M140 S60", "M104 S210", "G28", "M190 S60", "M109 S210")]
    assert order == sorted(order) and order[-1] < first_e
    assert lines[-2:] == ["M104 S0", "M140 S0"]
    assert verify_program(text, machine, toolpath).position < 0.011     # G28 is not a move


def test_machine_start_and_end_gcode_are_written_and_checked():
    from freecad_conformal.post.program import post_toolpath
    data = shipped("trunnion_ac")
    data["start_gcode"] = ["M7", "G4 P1"]
    data["end_gcode"] = ["M9"]
    text = post_toolpath(samples.tilted_ring(), machine_from_dict(data)).text
    lines = moves_and_codes(text)
    assert lines.index("G4 P1") < next(i for i, l in enumerate(lines) if l.startswith("G0"))
    assert lines[-4:] == ["M9", "G94", "M5", "M2"]
    data["start_gcode"] = ["M7 ; flood"]
    with pytest.raises(KinematicsError, match="start_gcode: 'M7 ; flood' must be one G-code"):
        machine_from_dict(data)


def test_linuxcnc_mandrel_program_switches_the_extruder_and_says_how(tmp_path):
    from freecad_conformal.post.program import post_toolpath
    from tests.unit.test_post_dialects import check_with_rs274
    machine = load_machine("rotary_mandrel")
    result = post_toolpath(samples.mandrel_helix(turns=3), machine, "linuxcnc")
    lines = moves_and_codes(result.text)
    on, off = lines.index("M64 P0"), lines.index("M65 P0")
    deposit_moves = [i for i, line in enumerate(lines) if "G1 " in line]
    assert on < deposit_moves[0] and deposit_moves[-1] < off
    assert not any(" E" in line for line in lines) and "deposited by digital output 0" in result.text
    assert "(before starting: hotend at 210 C, homed" in result.text
    check_with_rs274(result, tmp_path)


def multi_tool_toolpath():
    from freecad_conformal.toolpath import ToolpathBuilder
    builder = ToolpathBuilder(part="two tools")
    builder.event("tool_change", tool=1)
    builder.add_segment([[0, 0, 20], [0, 0, 2]], kind="travel", feed=3000, tool=1)
    builder.add_segment([[0, 0, 2], [10, 0, 2]], kind="cure", feed=300, tool=1, flow=0.01)
    builder.event("tool_change", tool=3)
    builder.add_segment([[10, 0, 2], [10, 10, 2]], kind="cure", feed=300, tool=3, flow=0.01)
    return builder.build()


def test_every_tool_change_applies_that_tools_length_and_rewrites_all_axes(tmp_path):
    from freecad_conformal.post.program import post_toolpath
    from tests.unit.test_post_dialects import check_with_rs274
    result = post_toolpath(multi_tool_toolpath(), load_machine("trunnion_ac"))
    lines = moves_and_codes(result.text)
    for tool in (1, 3):
        i = lines.index(f"T{tool} M6")
        assert lines[i + 1] == f"G43 H{tool}"
        assert all(f" {axis}" in lines[i + 2] for axis in "XYZAC"), lines[i + 2]
    check_with_rs274(result, tmp_path)      # rs274 applies its own tool table's lengths


def test_tool_change_goes_to_the_machines_tool_change_height_first():
    from freecad_conformal.post.program import post_toolpath
    data = shipped("trunnion_ac")
    data["tool_change_z"] = 0
    lines = moves_and_codes(post_toolpath(multi_tool_toolpath(), machine_from_dict(data)).text)
    i = lines.index("T3 M6")
    assert lines[i - 1] == "G53 G0 Z0"


DATA_MACHINES = __import__("pathlib").Path(__file__).parent / "data" / "machines"


def test_free_angle_at_the_pole_takes_a_value_that_fits_the_linear_limits():
    data = shipped("trunnion_ac")
    data["linear_axes"]["X"]["limits"] = [-5, 5]
    machine = machine_from_dict(data)
    joints = inverse(machine, np.array([[20.0, 0.0, 0.0]]), np.array([[0.0, 0.0, 1.0]]))
    assert abs(joints[0, 0]) <= 5 and abs(joints[0, 3]) < 1e-12


def test_nutating_table_takes_the_other_solution_when_one_leaves_the_limits():
    from freecad_conformal.errors import KinematicsError
    from freecad_conformal.post.kinematics import positions_for, rotary_candidates
    data = json.loads((DATA_MACHINES / "nutating_table.json").read_text())
    data["linear_axes"]["X"]["limits"] = [-40, 40]
    data["linear_axes"]["Y"]["limits"] = [-40, 40]
    machine = machine_from_dict(data)
    rng = np.random.default_rng(7)
    points = rng.uniform(-45, 45, (3000, 3))
    tilt = np.radians(rng.uniform(0, 85, 3000))
    turn = rng.uniform(0, 2 * np.pi, 3000)
    axes = np.column_stack([np.sin(tilt) * np.cos(turn), np.sin(tilt) * np.sin(turn), np.cos(tilt)])
    candidates = rotary_candidates(machine, axes, str)
    fits = np.zeros((3000, 2), dtype=bool)
    for branch in range(2):
        joints = np.column_stack([np.zeros((3000, 3)), np.nan_to_num(candidates[:, branch])])
        xyz = positions_for(machine, points, joints)
        fits[:, branch] = (np.abs(xyz[:, :2]) <= 40).all(axis=1)
    only_other = np.flatnonzero(fits.any(axis=1) & ~fits.all(axis=1))
    assert len(only_other) > 20                    # the case exists often enough to matter
    refused = 0
    for i in np.flatnonzero(fits.any(axis=1)):
        try:
            inverse(machine, points[i:i + 1], axes[i:i + 1])
        except KinematicsError:
            refused += 1
    assert refused == 0


def _edge_path(*points):
    from freecad_conformal.toolpath import ToolpathBuilder
    builder = ToolpathBuilder(part="edge of the travel")
    builder.add_segment(np.array(points, dtype=float), np.tile([0.0, 0.0, 1.0], (len(points), 1)),
                        kind="deposit", feed=1000.0)
    return builder.build()


def test_free_angle_holds_one_value_over_a_run_that_leaves_the_travel():
    # a vertical tool (C free) along Y = 300.5 on a ±300 mm trunnion: picked pose by pose C
    # took +5° and -5° in turn and the post refused a "rotary jump"; one C fits the whole run
    from freecad_conformal.post.program import post_toolpath
    from freecad_conformal.post.verify import verify_program
    machine = load_machine("trunnion_ac")
    toolpath = _edge_path((0, 290, 0), (0, 300.5, 0), (10, 300.5, 0))
    text = post_toolpath(toolpath, machine).text
    c_words = {float(w) for w in re.findall(r"^G[01].* C(-?[\d.]+)", text, re.M)}
    assert len(c_words) == 1 and c_words != {0.0}, c_words
    deviation = verify_program(text, machine, toolpath)
    assert deviation.position < 0.01


def test_point_outside_the_travel_is_named_not_called_a_rotary_jump():
    # from a corner that fits only at C = 0 to a point that needs C turned: no one C fits
    from freecad_conformal.errors import PostError
    from freecad_conformal.post.program import post_toolpath
    toolpath = _edge_path((299, 299, 0), (0, 300.5, 0))
    with pytest.raises(PostError, match=r"the tip at \(.*\) is outside the linear travel with "
                                        r"the angles kept \(Y = 300\.\d+ mm > 300\)") as error:
        post_toolpath(toolpath, load_machine("trunnion_ac"))
    assert "rotary limit" not in str(error.value)


@pytest.mark.parametrize("name", ["head_head_cb", "offset_table_bc", "nutating_table"])
@pytest.mark.parametrize("make", [samples.tilted_ring,
                                  lambda: samples.dome_spiral(1200, turns=1.5, segments=3,
                                                              max_tilt_deg=40)])
def test_new_kinematic_types_post_and_verify_within_tolerance_without_code(name, make, tmp_path):
    """Machine files of kinds the code was not written for: the replay stays within the
    tolerance itself (no slack), and LinuxCNC's interpreter moves to the same joints."""
    from freecad_conformal.post.program import post_toolpath
    from freecad_conformal.post.verify import verify_program
    from tests.unit.test_post_dialects import check_with_rs274
    machine, toolpath = load_machine(DATA_MACHINES / f"{name}.json"), make()
    result = post_toolpath(toolpath, machine)
    deviation = verify_program(result.text, machine, toolpath)
    assert deviation.position <= 0.01 and math.degrees(deviation.angle) <= 0.05
    check_with_rs274(result, tmp_path)


def test_toolpath_that_switches_its_extruder_gets_no_extra_switching():
    from freecad_conformal.post.program import post_toolpath
    from freecad_conformal.toolpath import ToolpathBuilder
    builder = ToolpathBuilder()
    builder.add_segment([[0, 0, 5], [0, 0, 1]], kind="travel", feed=3000)
    builder.add_segment([[0, 0, 1], [5, 0, 1]], kind="deposit", feed=600, flow=0.1)
    builder.event("extruder_on")               # after the first deposit, on purpose
    builder.add_segment([[5, 0, 1], [5, 5, 1]], kind="deposit", feed=600, flow=0.1)
    builder.event("extruder_off")
    text = post_toolpath(builder.build(), load_machine("trunnion_ac")).text
    assert text.count("M64 P0") == text.count("M65 P0") == 1


def tilted_two_tools():
    from freecad_conformal.toolpath import ToolpathBuilder
    tilt = np.array([0.0, -0.5, 0.8660254037844386])           # 30° about X: A moves
    builder = ToolpathBuilder(part="two tools, tilted")
    builder.event("tool_change", tool=1)
    builder.add_segment([[0, 0, 20], [0, 0, 2]], axes=tilt, kind="travel", feed=3000, tool=1)
    builder.add_segment([[0, 0, 2], [10, 0, 2]], axes=tilt, kind="cure", feed=300, tool=1)
    builder.event("tool_change", tool=3)
    builder.add_segment([[10, 0, 2], [10, 10, 2]], axes=tilt, kind="cure", feed=300, tool=3)
    return builder.build()


def test_head_machine_measures_its_pivot_from_each_tools_tip():
    from freecad_conformal.post.program import post_toolpath
    from freecad_conformal.post.verify import verify_program
    data = shipped("head_a_table_c")
    data["tool_lengths"] = {"1": 0, "3": 12}
    machine, toolpath = machine_from_dict(data), tilted_two_tools()
    result = post_toolpath(toolpath, machine)
    assert "G43" not in result.text            # the tool tilts: no length along Z
    last = result.blocks.joints[-1]
    tip, _ = __import__("freecad_conformal.post.kinematics", fromlist=["forward"]).forward(
        machine.for_tool(3), last[None])
    assert np.allclose(tip[0], [10, 10, 2], atol=1e-9)
    assert verify_program(result.text, machine, toolpath).position <= 0.01
    # replayed as if every tool were the reference one, the third tool misses by its length
    same_length = machine_from_dict(shipped("head_a_table_c"))
    assert verify_program(result.text, same_length, toolpath).position > 5.0


def test_head_machine_without_the_length_of_a_tool_it_uses_is_refused():
    from freecad_conformal.post.program import post_toolpath
    data = shipped("head_a_table_c")
    data["tool_lengths"] = {"1": 0}
    with pytest.raises(KinematicsError, match="tool_lengths for tools \\[1\\], but not for tool 3"):
        post_toolpath(tilted_two_tools(), machine_from_dict(data))
