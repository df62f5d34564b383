"""resources/macros/ConformalBatch.FCMacro run by the real FreeCADCmd."""
from __future__ import annotations

import csv
import os
import shutil
import subprocess
import sysconfig
from pathlib import Path

import pytest

from tests.geometry.batch_parts import make_parts

PROJECT_ROOT = Path(__file__).resolve().parents[2]
MACRO = PROJECT_ROOT / "resources" / "macros" / "ConformalBatch.FCMacro"

#: A cold FreeCADCmd start is 1-2 s; the slack is for a 2-core machine shared by test runs.
FREECADCMD_TIMEOUT_S = 120.0


def _freecadcmd(arguments: list[str], cwd: Path) -> subprocess.CompletedProcess:
    program = shutil.which("freecadcmd") or shutil.which("FreeCADCmd")
    if program is None:
        pytest.skip("freecadcmd is not installed (Debian: apt-get install freecad)")
    home = cwd / "freecad-home"
    home.mkdir(exist_ok=True)
    # shapely is not a Debian dependency of FreeCAD: the test venv's packages through PYTHONPATH
    site = sysconfig.get_paths()["purelib"]
    env = {**os.environ, "FREECAD_USER_HOME": str(home), "HOME": str(home),
           "PYTHONPATH": os.pathsep.join(p for p in (site, os.environ.get("PYTHONPATH", "")) if p)}
    return subprocess.run([program, str(MACRO), *arguments], cwd=cwd, env=env, text=True,
                          capture_output=True, timeout=FREECADCMD_TIMEOUT_S)


@pytest.mark.slow
def test_macro_plans_the_parts_and_exits_with_the_batch_code(tmp_path):
    make_parts(tmp_path / "parts")
    run = _freecadcmd(["--", "parts/box.step", "parts/two.FCStd", "parts/broken.step",
                       "--layer", "1", "--bead-width", "1", "-o", "out", "--workers", "2"], tmp_path)
    log = run.stdout + run.stderr
    assert run.returncode == 1, log
    assert "3 ok, 1 failed" in run.stdout, log
    with open(tmp_path / "out" / "batch-report.csv", newline="", encoding="utf-8") as handle:
        rows = {row["part"]: row for row in csv.DictReader(handle)}
    assert [rows[name]["status"] for name in ("box.step", "two.FCStd#Left", "two.FCStd#Right")] == ["ok"] * 3
    assert rows["broken.step"]["error"].startswith("cannot read broken.step")
    for name in ("box.gcode", "two_Left.gcode", "two_Right.gcode"):
        assert (tmp_path / "out" / name).stat().st_size > 0
    # The macro ends FreeCADCmd itself: it must not go on to import the inputs as documents.
    assert "Exception while processing file" not in log


@pytest.mark.slow
def test_spawned_workers_inside_freecadcmd_run_a_real_python(tmp_path):
    """FreeCAD 1.x cannot fork safely (OCCT 7.8's thread pool), so inside FreeCADCmd spawned
    workers must start a Python of FreeCAD's own, not the FreeCADCmd binary."""
    make_parts(tmp_path / "parts")
    run = _freecadcmd(["--", "parts/box.step", "parts/two.FCStd", "--layer", "1",
                       "--bead-width", "1", "-o", "out",
                       "--workers", "2", "--start-method", "spawn"], tmp_path)
    log = run.stdout + run.stderr
    assert run.returncode == 0, log
    assert "3 ok, 0 failed" in run.stdout, log


def test_macro_without_arguments_prints_how_to_call_it(tmp_path):
    run = _freecadcmd([], tmp_path)
    assert run.returncode == 0
    assert "freecadcmd ConformalBatch.FCMacro -- PARTS..." in run.stdout + run.stderr


def test_macro_passes_usage_errors_through(tmp_path):
    run = _freecadcmd(["--", "--layer", "1"], tmp_path)
    assert run.returncode == 2
    assert "the following arguments are required: INPUT, -o/--output-dir" in run.stderr
