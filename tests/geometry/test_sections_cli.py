"""`python -m freecad_conformal sections` and `demo`: output, JSON format, exit codes."""
from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def run_cli(*args: str, cwd: Path = ROOT) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "freecad_conformal", *args], cwd=cwd,
                          capture_output=True, text=True, timeout=300)


def test_sections_table_and_json(tmp_path, App, Part):
    part = tmp_path / "sphere.brep"
    Part.makeSphere(5).exportBrep(str(part))
    out = tmp_path / "s.json"
    result = run_cli("sections", str(part), "--layer", "2", "--json", str(out))
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert "5 planar sections" in lines[0]
    data = json.loads(out.read_text())
    assert data["direction"] == [0.0, 0.0, 1.0]
    heights = [layer["height"] for layer in data["layers"]]
    assert heights == pytest.approx([-4, -2, 0, 2, 4])
    for layer in data["layers"]:
        assert layer["area"] == pytest.approx(math.pi * (25 - layer["height"] ** 2), rel=1e-9)
        assert layer["centroid"] == pytest.approx([0, 0, layer["height"]], abs=1e-9)
        [loop] = layer["loops"]
        assert loop["outer"] is True and len(loop["points"]) > 16


def test_sections_direction_and_cylindrical(tmp_path, App, Part):
    part = tmp_path / "tube.brep"
    Part.makeCylinder(10, 20).cut(Part.makeCylinder(5, 20)).exportBrep(str(part))
    along_x = run_cli("sections", str(part), "--heights", "0,9.5", "--direction", "1,0,0")
    assert along_x.returncode == 0, along_x.stderr
    out = tmp_path / "c.json"
    cylindrical = run_cli("sections", str(part), "--radii", "7", "--json", str(out))
    assert cylindrical.returncode == 0, cylindrical.stderr
    data = json.loads(out.read_text())
    assert data["kind"] == "cylindrical"
    assert data["layers"][0]["area"] == pytest.approx(2 * math.pi * 7 * 20, rel=1e-9)


@pytest.mark.parametrize("args, message", [
    (["sections", "missing.step"], "not found"),
    (["sections", "{part}", "--layer", "0"], "layer height (--layer-height / LayerHeight) must be > 0"),
    (["sections", "{part}", "--direction", "0,0,0"], "direction (--direction / Direction) must be"),
    (["sections", "{part}", "--radii", "2", "--layer", "1"], "--layer-height and --heights are for planar"),
    (["sections", "{part}", "--heights", "0.5", "--layer", "1"], "not both"),
    (["sections", "{shell}"], "not a solid"),      # an open shell (a closed one is sewn)
])
def test_bad_input_exits_non_zero_without_output(tmp_path, App, Part, args, message):
    part = tmp_path / "box.brep"
    Part.makeBox(1, 1, 1).exportBrep(str(part))
    shell = tmp_path / "shell.brep"
    Part.Shell(Part.makeBox(1, 1, 1).Faces[:5]).exportBrep(str(shell))
    out = tmp_path / "never.json"
    argv = [a.format(part=part, shell=shell) for a in args] + ["--json", str(out)]
    result = run_cli(*argv, cwd=tmp_path)
    assert result.returncode == 1
    assert message in result.stderr
    assert not out.exists()
    assert not list(tmp_path.glob("*.part"))


def test_unparsable_vector_is_named_before_the_part_is_read(tmp_path):
    result = run_cli("sections", "x.step", "--direction", "1,2")     # x.step does not exist
    assert result.returncode == 1
    assert "direction (--direction / Direction) must be a direction x,y,z" in result.stderr
    assert "not three numbers" in result.stderr
