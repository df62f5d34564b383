"""verify (replay through forward kinematics) and the post/verify command line, bad input."""
from __future__ import annotations

import math
import re

import numpy as np
import pytest

from freecad_conformal.cli import main
from freecad_conformal.errors import PostError
from freecad_conformal.post import samples
from freecad_conformal.post.machine import load_machine
from freecad_conformal.post.program import post_toolpath
from freecad_conformal.post.verify import verify_program
from freecad_conformal.post.rs274 import canonical_moves, rs274_path
from freecad_conformal.toolpath import ToolpathBuilder
from tests.unit.test_post_dialects import check_with_rs274

TOL, ATOL_DEG = 0.01, 0.05
SLACK = 1.05          # sampling in verify differs from the post's checks
ROUNDING = 1e-4       # four decimals in the G-code


@pytest.mark.parametrize("machine_name, make", [
    ("trunnion_ac", samples.tilted_ring), ("head_a_table_c", samples.tilted_ring),
    ("rotary_mandrel", lambda: samples.mandrel_helix(turns=2)),
    ("trunnion_ac", lambda: samples.dome_spiral(600, turns=3, segments=4)),
])
def test_posted_programs_replay_within_tolerance(machine_name, make, tmp_path):
    machine, toolpath = load_machine(machine_name), make()
    result = post_toolpath(toolpath, machine)
    if machine.dialect == "linuxcnc":
        check_with_rs274(result, tmp_path)
    deviation = verify_program(result.text, machine, toolpath)
    assert deviation.position <= TOL * SLACK + ROUNDING
    assert math.degrees(deviation.angle) <= ATOL_DEG * SLACK + ROUNDING


def test_verify_catches_a_wrong_block():
    machine, toolpath = load_machine("trunnion_ac"), samples.tilted_ring()
    text = post_toolpath(toolpath, machine).text
    lines = text.splitlines()
    target = next(i for i, l in enumerate(lines) if l.startswith("G1") and " A" in l and " Z" in l)
    lines[target] = re.sub(r" Z(-?[\d.]+)", lambda m: f" Z{float(m.group(1)) + 0.2:.4f}", lines[target])
    lines[target] = re.sub(r" A(-?[\d.]+)", lambda m: f" A{float(m.group(1)) + 1:.4f}", lines[target])
    deviation = verify_program("\n".join(lines), machine, toolpath)
    assert deviation.position > 0.1 and math.degrees(deviation.angle) > 0.5


def test_verify_rejects_unreadable_programs():
    machine, toolpath = load_machine("three_axis"), samples.flat_square()
    with pytest.raises(PostError, match="no G0/G1 move"):
        verify_program("M2\n", machine, toolpath)
    with pytest.raises(PostError, match="arcs"):
        verify_program("G0 X0 Y0 Z0\nG2 X1 Y1 I1\n", machine, toolpath)


def test_cli_post_and_verify(tmp_path, capsys):
    toolpath_file = tmp_path / "ring.npz"
    samples.tilted_ring().save(toolpath_file)
    out = tmp_path / "ring.ngc"
    assert main(["post", str(toolpath_file), "--machine", "trunnion_ac", "-o", str(out)]) == 0
    assert out.read_text().startswith("(Conformal post-processor)")
    # the time a plan of this toolpath reports (corners, the machine's feed limits)
    from freecad_conformal.paths.timing import estimate_time

    machine = load_machine("trunnion_ac")
    seconds = estimate_time(samples.tilted_ring(), machine.acceleration,
                            max_feed=machine.max_feed, rapid_feed=machine.rapid_feed)
    assert f"[{seconds:.1f} s])" in out.read_text().splitlines()[5]
    if rs274_path() is not None:                      # every LinuxCNC program goes through rs274
        assert len(canonical_moves(out)[0]) > 10
    assert main(["verify", str(out), "--machine", "trunnion_ac", "--toolpath", str(toolpath_file),
                 "--max-position", "0.0106", "--max-angle", "0.06"]) == 0
    assert "largest position deviation" in capsys.readouterr().out
    machine_path = load_machine("head_a_table_c").source
    out2 = tmp_path / "ring.nc"
    assert main(["post", str(toolpath_file), "--machine", machine_path, "--dialect", "linuxcnc",
                 "-o", str(out2)]) == 0
    if rs274_path() is not None:
        assert len(canonical_moves(out2)[0]) > 10


def _with_jerk(toolpath, jerk: str):
    import dataclasses

    return dataclasses.replace(toolpath, metadata={**toolpath.metadata, "jerk": jerk})


def test_post_says_the_time_at_the_jerk_the_plan_recorded(tmp_path):
    """A plan records its jerk in the toolpath: posted later, the program says the plan's
    time, not the default jerk's."""
    from freecad_conformal.paths.timing import DEFAULT_JERK, estimate_time

    machine = load_machine("trunnion_ac")
    builder = ToolpathBuilder()
    # a zigzag: its sharp turns slow down by the jerk
    builder.add_segment([[x, 10.0 * (k % 2), 5.0] for k, x in enumerate(np.arange(0.0, 20.0, 0.5))],
                        kind="deposit", feed=3000, flow=0.08)
    zigzag = builder.build()
    toolpath_file, out = tmp_path / "zigzag.npz", tmp_path / "zigzag.ngc"
    _with_jerk(zigzag, "2.5").save(toolpath_file)
    assert main(["post", str(toolpath_file), "--machine", "trunnion_ac", "-o", str(out)]) == 0
    seconds = {jerk: estimate_time(zigzag, machine.acceleration, jerk, max_feed=machine.max_feed,
                                   rapid_feed=machine.rapid_feed) for jerk in (2.5, DEFAULT_JERK)}
    assert f"{seconds[2.5]:.1f}" != f"{seconds[DEFAULT_JERK]:.1f}"
    assert f"[{seconds[2.5]:.1f} s])" in out.read_text().splitlines()[5]
    # the Post object's time (its property and its program's header) is the same
    from freecad_conformal.objects.post_feature import compute_post

    posted = compute_post({"toolpath": toolpath_file.read_bytes(), "machine": "trunnion_ac",
                           "dialect": "linuxcnc", "tolerance": TOL,
                           "angular_tolerance": math.radians(ATOL_DEG)}, lambda *_: None)
    assert posted["seconds"] == seconds[2.5]
    assert f"[{seconds[2.5]:.1f} s])" in posted["gcode"].splitlines()[5]


@pytest.mark.parametrize("jerk", ["fast", "0", "-1", "nan"])
def test_a_toolpath_recording_no_jerk_is_refused_by_name(tmp_path, capsys, jerk):
    toolpath_file, out = tmp_path / "ring.npz", tmp_path / "ring.ngc"
    _with_jerk(samples.tilted_ring(), jerk).save(toolpath_file)
    assert main(["post", str(toolpath_file), "--machine", "trunnion_ac", "-o", str(out)]) != 0
    assert f"toolpath metadata 'jerk' must be a jerk in mm/s (finite, above 0), got '{jerk}'" \
        in capsys.readouterr().err
    assert not out.exists()


def bad_toolpath_file(tmp_path):
    builder = ToolpathBuilder()
    # 250 mm from the table's axis: beyond X/Y ±150 mm at every C (the corner is 212 mm out)
    builder.add_segment([[0, 0, 10], [250, 0, 10]], kind="cure", feed=100)
    path = tmp_path / "far.npz"
    builder.build().save(path)
    return path


@pytest.mark.parametrize("arguments, message", [
    (["missing.npz", "--machine", "trunnion_ac"], "does not exist"),
    (["GOOD", "--machine", "no_such_machine"], "unknown machine"),
    (["GOOD", "--machine", "trunnion_ac", "--dialect", "fanuc"], "unknown G-code dialect"),
    (["FAR", "--machine", "head_a_table_c"], "outside the limits"),
    (["GOOD", "--machine", "three_axis"], "not reachable"),
])
def test_cli_bad_input_leaves_no_file(tmp_path, capsys, arguments, message):
    good = tmp_path / "good.npz"
    samples.tilted_ring().save(good)
    far = bad_toolpath_file(tmp_path)
    arguments = [str(good) if a == "GOOD" else str(far) if a == "FAR" else
                 str(tmp_path / a) if a.endswith(".npz") else a for a in arguments]
    before = sorted(p.name for p in tmp_path.iterdir())
    out = tmp_path / "out.ngc"
    assert main(["post", *arguments, "-o", str(out)]) == 1
    assert message in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_toolpath_with_nan_is_rejected_before_posting():
    builder = ToolpathBuilder()
    builder.add_segment([[0, 0, 0], [1, 1, 1]])
    toolpath = builder.build()
    toolpath.points[1, 2] = np.nan
    with pytest.raises(PostError, match="not finite at segment 0 point 1"):
        post_toolpath(toolpath, load_machine("three_axis"))
