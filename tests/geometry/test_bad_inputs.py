"""A corpus of a new user's mistakes: each gives exit code 1 or 2, a message naming the thing
and the value, no traceback, nothing written, and every input left as it was."""
from __future__ import annotations

import hashlib
import os
from pathlib import Path

import pytest

from freecad_conformal.cli import main


@pytest.fixture
def folder(tmp_path, Part):
    """A folder with a box part, a toolpath, a G-code program, a corrupt FCStd and a subfolder."""
    from freecad_conformal.toolpath import ToolpathBuilder

    import numpy as np

    Part.makeBox(20, 20, 10).exportStep(str(tmp_path / "box.step"))
    builder = ToolpathBuilder(part="line")
    builder.add_segment(np.array([[0.0, 0, 0], [10, 0, 0]]), np.array([[0.0, 0, 1], [0, 0, 1]]),
                        kind="deposit", feed=600.0)
    builder.build().save(tmp_path / "t.npz")
    (tmp_path / "p.ngc").write_text("G21\nG90\nG1 X1 Y1 Z1 F600\nM2\n")
    (tmp_path / "broken.FCStd").write_bytes(b"PK\x03\x04 this is not a FreeCAD document")
    (tmp_path / "sub").mkdir()
    Part.makeSphere(10).exportStep(str(tmp_path / "ball.step"))
    (tmp_path / "empty.step").write_text("")
    (tmp_path / "garbage.step").write_text("ISO-10303-21;\nthis is not step\n")
    (tmp_path / "text.brep").write_text("hello")
    (tmp_path / "text.step").write_text("solid part\nendsolid part\n")   # an STL renamed
    (tmp_path / "zero.npz").write_bytes(b"")
    Part.makeBox(10, 10, 10).Faces[0].exportBrep(str(tmp_path / "face.brep"))
    (tmp_path / "twice.csv").write_text("A,B,A,y\n1,1,1,2\n-1,1,-1,3\n1,-1,1,4\n-1,-1,-1,5\n")
    (tmp_path / "ragged.csv").write_text("A,B,y\n1,1,2,9,9\n-1,1,3\n1,-1,4\n-1,-1,5\n")
    Part.makeBox(10, 10, 10).Edges[0].exportBrep(str(tmp_path / "edge.brep"))
    Part.makeCompound(Part.makeBox(10, 10, 10).Faces[1:]).exportBrep(str(tmp_path / "open.brep"))
    # files saved in another encoding than UTF-8 (Latin-1, UTF-16 from a spreadsheet)
    (tmp_path / "latin1.csv").write_bytes("A,B,y\n1,1,2\n-1,1,3 \xb5m\n".encode("latin-1"))
    (tmp_path / "utf16.json").write_bytes('{"factors": []}'.encode("utf-16"))
    (tmp_path / "latin1.svg").write_bytes("M0 0 L5 0 L5 5 Z \xe9".encode("latin-1"))
    (tmp_path / "ok.csv").write_text("A,B,y\n1,1,2\n-1,1,3\n1,-1,4\n-1,-1,5\n")
    return tmp_path


def _snapshot(folder: Path) -> dict[str, str]:
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


CASES = [
    # outputs that would replace an input
    (["plan", "box.step", "-o", "box.step"], ["-o/--output box.step is the input file", "overwritten"]),
    (["plan", "box.step", "-o", "x.ngc", "--png", "box.step"], ["--png", "input file"]),
    (["sections", "box.step", "--layer", "1", "--json", "box.step"], ["--json box.step", "input"]),
    (["decompose", "box.step", "--json", "box.step"], ["--json box.step", "input"]),
    (["post", "t.npz", "--machine", "trunnion_ac", "-o", "t.npz"], ["t.npz is the input file"]),
    (["feature", "box.step", "--face", "Face1", "--kind", "rods", "-o", "box.step"],
     ["box.step is the input file"]),
    (["mandrel", "box.step", "-o", "box.step"], ["box.step is the input file"]),
    (["stream", "p.ngc", "--port", "/dev/ttyNOPE0", "--state", "p.ngc"], ["--state p.ngc", "input"]),
    (["stream", "p.ngc", "--port", "/dev/ttyNOPE0", "--log", "p.ngc"], ["--log p.ngc", "input"]),
    # outputs that cannot be written where asked
    (["plan", "box.step", "-o", "nowhere/x.ngc"], ["nowhere/x.ngc", "folder nowhere does not exist"]),
    (["plan", "box.step", "-o", "sub"], ["-o/--output sub is a folder"]),
    (["plan", "box.step", "-o", "x.ngc", "--summary", "x.ngc"], ["same file x.ngc"]),
    (["plan", "box.step", "-o", "x.ngc", "--summary", "box.step/s.txt"], ["does not exist"]),
    (["plan", "box.step", "-o", "x.ngc", "--toolpath", "nowhere/t.npz"], ["--toolpath", "nowhere"]),
    (["batch", "box.step", "-o", "out", "--suffix", "./../../X.gcode"], ["folder separator"]),
    (["batch", "box.step", "-o", "nowhere/out"], ["parent nowhere does not exist"]),
    (["demo", "--out", "demo", "--machine", "nosuch"], ["nosuch"]),
    (["demo", "--out", "demo", "--tool", "nosuch"], ["nosuch"]),
    (["demo", "--out", "nowhere/demo"], ["parent nowhere does not exist"]),
    # inputs that cannot be read
    (["plan", "broken.FCStd", "-o", "x.ngc"], ["cannot read broken.FCStd"]),
    (["plan", "missing.step", "-o", "x.ngc"], ["missing.step"]),
    # settings out of range, named with their flag and value, before any geometry work
    (["plan", "box.step", "-o", "x.ngc", "--layer-height", "0"], ["--layer-height", "got 0"]),
    (["plan", "box.step", "-o", "x.ngc", "--solid-layers", "-3"], ["--solid-layers", "got -3"]),
    (["plan", "box.step", "-o", "x.ngc", "--root", "nan,0,1"], ["--root", "'nan,0,1'"]),
    (["plan", "box.step", "-o", "x.ngc", "--layer-height", "inf"], ["--layer-height", "finite"]),
    (["feature", "box.step", "--face", "Face1", "--kind", "rods", "-o", "x.npz",
      "--build-direction", "0,0,0"], ["--build-direction", "'0,0,0'"]),
    (["feature", "box.step", "--face", "Face1", "--kind", "rods", "-o", "x.npz",
      "--rings", "-3"], ["--rings", "got -3"]),
    (["feature", "box.step", "--face", "Face1", "--kind", "rods", "-o", "x.npz",
      "--feed", "-5"], ["--feed", "got -5"]),
    (["feature", "box.step", "--face", "Face1", "--kind", "rods", "-o", "x.npz",
      "--layer", "nan"], ["--layer", "finite"]),
]


P = ["plan", "box.step", "-o", "x.ngc"]
S = ["sections", "box.step"]
R = ["feature", "ball.step", "--face", "Face1", "-o", "x.npz", "--kind"]
CASES += [
    # unreadable parts
    (["plan", "empty.step", "-o", "x.ngc"], ["empty.step is empty (0 bytes)"]),
    (["plan", "text.step", "-o", "x.ngc"], ["text.step is not a STEP file", "ISO-10303-21;"]),
    (["plan", "garbage.step", "-o", "x.ngc"], ["cannot read garbage.step", "damaged"]),
    (["plan", "text.brep", "-o", "x.ngc"], ["text.brep holds no shape"]),
    (["plan", "sub", "-o", "x.ngc"], ["not found: sub"]),
    # library and machine names
    (P + ["--machine", "nosuch"], ["unknown machine 'nosuch'"]),
    (P + ["--tool", "nosuch"], ["no tool 'nosuch'"]),
    (P + ["--material", "nosuch"], ["no settings for material 'nosuch'"]),
    (P + ["--dialect", "nosuch"], ["unknown G-code dialect 'nosuch'"]),
    (P + ["--layer-mode", "fast"], ["--layer-mode", "'fast'"]),
    # plan settings
    (P + ["--layer-min", "-1"], ["--layer-min", "got -1"]),
    (P + ["--layer-min", "0.3", "--layer-max", "0.1", "--layer-mode", "adaptive"],
     ["minimum layer height 0.3 mm exceeds the maximum 0.1 mm"]),
    (P + ["--infill", "-1"], ["--infill", "got -1"]),
    (P + ["--infill-angle", "nan"], ["--infill-angle", "finite"]),
    (P + ["--perimeters", "2.5"], ["--perimeters", "'2.5'"]),
    (P + ["--bead-width", "0"], ["--bead-width", "got 0"]),
    (P + ["--max-cusp", "0"], ["--max-cusp", "got 0"]),
    (P + ["--min-speed", "0"], ["--min-speed", "got 0"]),
    (P + ["--min-layer-time", "-1"], ["--min-layer-time", "got -1"]),
    (P + ["--solid-below-area", "-1"], ["--solid-below-area", "got -1"]),
    (P + ["--max-volume-difference", "0"], ["--max-volume-difference", "got 0"]),
    (P + ["--mapping", "linear"], ["--mapping linear applies to mandrel builds only"]),
    # sections
    (S + ["--layer", "-1"], ["layer height", "-1"]),
    (S + ["--layer", "nan"], ["layer height", "nan"]),
    (S + ["--heights", "a,b"], ["--heights", "'a,b'"]),
    (S + ["--radii=-1"], ["radii", "-1"]),
    (S + ["--direction", "0,0,0"], ["zero vector"]),
    (S + ["--direction", "nan,0,1"], ["not finite", "nan"]),
    (S + ["--chord", "0"], ["chord tolerance", "0"]),
    (S + ["--workers", "-1"], ["--workers", "-1"]),
    (S + ["--layer", "1", "--json", "sub"], ["--json sub is a folder"]),
    # decompose
    (["decompose", "box.step", "--overhang", "95"], ["allowed overhang (--overhang", "got 95"]),
    (["decompose", "box.step", "--overhang", "nan"], ["allowed overhang (--overhang", "finite"]),
    (["decompose", "box.step", "--tool", "nosuch"], ["no tool 'nosuch'"]),
    (["decompose", "box.step", "--method", "nosuch"], ["--method", "'nosuch'"]),
    (["decompose", "box.step", "--step-dir", "nowhere/deep"], ["parent nowhere does not exist"]),
    # post and verify
    (["post", "t.npz", "--machine", "nosuch", "-o", "x.ngc"], ["unknown machine 'nosuch'"]),
    (["post", "zero.npz", "--machine", "trunnion_ac", "-o", "x.ngc"], ["zero.npz is not a Conformal toolpath"]),
    (["post", "p.ngc", "--machine", "trunnion_ac", "-o", "x.ngc"], ["p.ngc is not a Conformal toolpath"]),
    (["post", "missing.npz", "--machine", "trunnion_ac", "-o", "x.ngc"], ["missing.npz does not exist"]),
    (["post", "t.npz", "--machine", "trunnion_ac", "-o", "x.ngc", "--tolerance", "0"],
     ["--tolerance", "got 0"]),
    (["post", "t.npz", "--machine", "trunnion_ac", "-o", "x.ngc", "--angular-tolerance", "inf"],
     ["--angular-tolerance", "finite"]),
    (["verify", "p.ngc", "--machine", "trunnion_ac", "--toolpath", "t.npz", "--max-position",
      "nan"], ["--max-position", "finite"]),
    (["verify", "p.ngc", "--machine", "trunnion_ac", "--toolpath", "zero.npz"], ["zero.npz"]),
    (["verify", "missing.ngc", "--machine", "trunnion_ac", "--toolpath", "t.npz"], ["missing.ngc"]),
    # features
    (["feature", "box.step", "--face", "Face99", "--kind", "rods", "-o", "x.npz"], ["Face99", "6 faces"]),
    (["feature", "box.step", "--face", "nonsense", "--kind", "rods", "-o", "x.npz"], ["'nonsense'"]),
    (R + ["rods", "--spacing", "0"], ["--spacing", "got 0"]),
    (R + ["rods", "--rod-length", "inf"], ["--rod-length", "finite"]),
    (R + ["shell", "--width", "0"], ["--width", "got 0"]),
    (R + ["pattern", "--at", "nan,nan"], ["--at", "finite"]),
    (R + ["rods", "--tool", "nosuch"], ["no tool 'nosuch'"]),
    (R + ["rods", "--gcode", "nowhere/x.ngc"], ["--gcode", "nowhere"]),
    (["mandrel", "box.step", "-o", "x.ngc", "--machine", "nosuch"], ["unknown machine 'nosuch'"]),
    (["stream", "p.ngc", "--port", "/dev/ttyNOPE0", "--baud", "-5"], ["speed (baud) (--baud) must be >= 1", "-5"]),
    (["stream", "p.ngc", "--port", "/dev/ttyNOPE0", "--baud", "1.5"], ["--baud", "1.5"]),
    (["demo", "--out", "d", "--layer", "0"], ["section spacing (--layer) must be > 0", "got 0"]),
    (["demo", "--out", "d", "--plan-layer", "-1"], ["layer height (--plan-layer)", "got -1"]),
    (["mandrel", "box.step", "-o", "x.ngc", "--angle", "inf"], ["raster angle (--angle) must be finite", "inf"]),
    (["mandrel", "box.step", "-o", "x.ngc", "--feed", "0"], ["print feed (--feed) must be > 0", "got 0"]),
    # batch, tools, demo
    (["batch", "box.step", "-o", "out", "--workers", "-1"], ["--workers", "-1"]),
    (["batch", "box.step", "-o", "out", "--time-limit", "-5"], ["--time-limit", "-5"]),
    # shapes that are not solids: said so, not "layer height larger than the part"
    (["plan", "face.brep", "-o", "x.ngc"], ["the part 'face' is not a solid: it is a Face"]),
    (["plan", "edge.brep", "-o", "x.ngc"], ["the part 'edge' is not a solid: it is an Edge"]),
    (["decompose", "face.brep"], ["not a solid", "Face"]),
    (["plan", "open.brep", "-o", "x.ngc"], ["not a solid", "only 5 faces that do not close",
                                            "export the part as STEP"]),
    # inputs in another encoding than UTF-8
    (["doe", "analyze", "latin1.csv", "--response", "y", "--no-plot"],
     ["latin1.csv is not UTF-8", "byte"]),
    (["doe", "analyze", "ok.csv", "--response", "y", "--design", "utf16.json", "--no-plot"],
     ["cannot read design utf16.json"]),
    (["feature", "box.step", "--face", "Face6", "--kind", "pattern", "--svg", "latin1.svg",
      "-o", "x.npz"], ["latin1.svg is not UTF-8"]),
    (["post", "t.npz", "--machine", "utf16.json", "-o", "x.ngc"], ["utf16.json"]),
    # design of experiments, tools, verify, decompose
    (["doe", "design", "--factors", "1"], ["2 to 25 factors", "got 1"]),
    (["doe", "analyze", "twice.csv", "--response", "y", "--no-plot"],
     ["column(s) A appear more than once"]),
    (["doe", "analyze", "ragged.csv", "--response", "y", "--no-plot"],
     ["ragged.csv, line 2: more values than the header's 3 columns"]),
    (["doe", "analyze", "ok.csv", "--response", "nosuch", "--no-plot"], ["no column 'nosuch'"]),
    (["doe", "analyze", "ok.csv", "--response", "y", "--alpha", "2", "--no-plot"],
     ["alpha must be in (0, 1)", "got 2"]),
    (["doe", "analyze", "ok.csv", "--response", "y", "--goal", "nominal", "--target", "nan",
      "--no-plot"], ["target", "finite", "nan"]),
    (["doe", "analyze", "missing.csv", "--response", "y", "--no-plot"], ["missing.csv"]),
    (["tools", "choose", "--rs", "-1", "--cd", "1", "--theta", "10"], ["rs must be > 0", "-1"]),
    (["tools", "export", "uv_small"], ["export file uv_small must end in .json",
                                       "tools export FILE.json uv_small"]),
    (["tools", "choose", "--rs", "10", "--cd", "nan", "--theta", "10"], ["curing depth", "nan"]),
    (["verify", "p.ngc", "--machine", "trunnion_ac", "--toolpath", "nosuch.npz"],
     ["nosuch.npz does not exist"]),
    (["verify", "p.ngc", "--machine", "trunnion_ac", "--toolpath", "t.npz", "--max-position",
      "nan"], ["--max-position", "nan"]),
    (["verify", "p.ngc", "--machine", "trunnion_ac", "--toolpath", "t.npz", "--max-angle",
      "-1"], ["--max-angle", "got -1"]),
    (["verify", "sub", "--machine", "trunnion_ac", "--toolpath", "t.npz"],
     ["program file sub is a folder"]),
    (["post", "sub", "--machine", "trunnion_ac", "-o", "x.ngc"], ["toolpath file sub is a folder"]),
    (["batch", "box.step", "-o", "out", "--time-limit", "nan"], ["--time-limit", "nan"]),
    (["batch", "box.step", "-o", "out", "--suffix", "gcode"], ["suffix must start with a dot"]),
    (["batch", "box.step", "-o", "box.step"], ["output folder box.step is a file"]),
    (["tools", "show", "nosuch"], ["no tool 'nosuch'"]),
    (["demo", "--sample", "nosuch", "--out", "demo"], ["unknown sample 'nosuch'"]),
]




def _schema_cases() -> list[tuple[list[str], list[str]]]:
    """Every number setting of every command's schema, given as nan and below its minimum:
    a setting that loses its check (or a command that stops checking) fails here."""
    from freecad_conformal.settings.decompose import DECOMPOSE_SETTINGS
    from freecad_conformal.settings.feature import FEATURE_SETTINGS
    from freecad_conformal.settings.mandrel import MANDREL_SETTINGS
    from freecad_conformal.settings.plan import PLAN_SETTINGS
    from freecad_conformal.settings.post import POST_SETTINGS, VERIFY_SETTINGS
    from freecad_conformal.settings.sections import SECTIONS_SETTINGS
    from freecad_conformal.settings.stream import STREAM_SETTINGS

    commands = [(["plan", "box.step", "-o", "x.ngc"], PLAN_SETTINGS),
                (["sections", "box.step"], SECTIONS_SETTINGS),
                (["mandrel", "box.step", "-o", "x.ngc"], MANDREL_SETTINGS),
                (["stream", "p.ngc", "--port", "/dev/ttyNOPE0"], STREAM_SETTINGS),
                (["feature", "ball.step", "--face", "Face1", "--kind", "rods", "-o", "x.npz"],
                 FEATURE_SETTINGS),
                (["decompose", "box.step"], DECOMPOSE_SETTINGS),
                (["post", "t.npz", "--machine", "trunnion_ac", "-o", "x.ngc"], POST_SETTINGS),
                (["verify", "p.ngc", "--machine", "trunnion_ac", "--toolpath", "t.npz"],
                 VERIFY_SETTINGS)]
    numbers = ("length", "angle", "speed", "area", "volume", "time", "feed", "percent", "int",
               "float")
    cases = []
    for command, settings in commands:
        for setting in settings:
            if setting.kind not in numbers or not setting.cli_flag:
                continue
            cases.append((command + [setting.cli_flag, "nan"], [setting.cli_flag, "nan"]))
            if setting.minimum is not None:
                below = setting.minimum if setting.open_minimum else setting.minimum - 1
                text = f"{below:g}"
                cases.append((command + [f"{setting.cli_flag}={text}"],
                              [setting.cli_flag, f"got {text}"]))
    return cases


CASES += _schema_cases()


@pytest.mark.parametrize("argv, words", CASES, ids=[" ".join(c[0][:6]) for c in CASES])
def test_a_mistake_is_named_and_nothing_is_written(folder, capsys, monkeypatch, argv, words):
    monkeypatch.chdir(folder)
    before = _snapshot(folder)
    try:
        code = main(argv)
    except SystemExit as exc:           # argparse's usage errors
        code = exc.code
    err = capsys.readouterr().err
    assert code in (1, 2), err
    assert "Traceback" not in err
    for word in words:
        assert word in err, err
    assert _snapshot(folder) == before, "an input changed or an output was written"


def test_batch_never_writes_over_a_part(folder, capsys, monkeypatch):
    """`batch D/box.step -o D --suffix .step` would write box.step's G-code over box.step."""
    monkeypatch.chdir(folder)
    before = (folder / "box.step").read_bytes()
    assert main(["batch", "box.step", "-o", ".", "--suffix", ".step", "--workers", "0"]) == 1
    assert (folder / "box.step").read_bytes() == before
    assert "input file" in (folder / "batch-report.csv").read_text()


def test_a_killed_runs_temporaries_are_cleaned_and_a_live_ones_kept(folder):
    from freecad_conformal.fileio import write_text_atomic

    dead = folder / ".x.ngc.999999999.abc.part"       # no process has this pid
    alive = folder / f".x.ngc.{os.getpid()}.abc.part"
    dead.write_text("half a program")
    alive.write_text("being written")
    write_text_atomic(folder / "x.ngc", "G21\n")
    assert not dead.exists() and alive.exists()
    assert (folder / "x.ngc").read_text() == "G21\n"


def test_several_outputs_appear_together_or_not_at_all(folder):
    from freecad_conformal.errors import OutputError
    from freecad_conformal.fileio import write_all

    with pytest.raises(OutputError, match="does not exist"):
        write_all({folder / "a.ngc": "G21\n", folder / "nowhere" / "a.png": b"png"})
    assert not (folder / "a.ngc").exists()
    assert not [p for p in folder.iterdir() if p.name.endswith(".part")]
    written = write_all({folder / "a.ngc": "G21\n", folder / "a.txt": "summary"})
    assert [p.name for p in written] == ["a.ngc", "a.txt"]


def test_faces_without_a_solid_are_sewn_and_the_user_is_told(tmp_path, Part, capsys):
    from freecad_conformal.geometry.solids import load_shape

    Part.Compound(Part.makeBox(10, 10, 10).Faces).exportIges(str(tmp_path / "faces.igs"))
    assert main(["sections", str(tmp_path / "faces.igs"), "--layer", "5"]) == 0
    assert "sewed 6 face(s) into 1 closed solid(s)" in capsys.readouterr().err
    assert load_shape(tmp_path / "faces.igs").Volume == pytest.approx(1000.0, rel=1e-9)


def test_a_part_that_keeps_the_reader_busy_ends_the_command(folder):
    """A damaged file can keep OCC's reader busy for minutes, out of Ctrl-C's reach: the
    command line gives up after CONFORMAL_READ_TIME_LIMIT seconds, naming the file."""
    import subprocess
    import sys
    import time

    stalling_reader = (
        "import runpy, sys, time\n"
        "from freecad_conformal.freecad_env import import_freecad\n"
        "_, Part = import_freecad()\n"
        "Part.read = lambda path: time.sleep(120)\n"
        "sys.argv = ['freecad_conformal', 'sections', 'box.step', '--json', 'r.json']\n"
        "runpy.run_module('freecad_conformal', run_name='__main__')\n")
    began = time.monotonic()
    result = subprocess.run([sys.executable, "-c", stalling_reader], cwd=folder,
                            env={**os.environ, "CONFORMAL_READ_TIME_LIMIT": "2"},
                            capture_output=True, text=True, timeout=100)
    assert result.returncode == 1, result.stderr
    assert "reading box.step took longer than 2 s" in result.stderr
    assert time.monotonic() - began < 60
    assert not (folder / "r.json").exists()


def test_a_part_with_a_loose_tolerance_is_named_when_read(tmp_path, Part, capsys):
    """OCC takes points within a vertex's tolerance as one: a Boolean with a degenerate
    operand left 13 mm on a 4 mm rod, whose sections then failed with nothing to say why."""
    loose = Part.makeBox(10, 20, 30)
    loose.fixTolerance(0.5, Part.Vertex)
    loose.exportBrep(str(tmp_path / "loose.brep"))
    Part.makeBox(10, 20, 30).exportBrep(str(tmp_path / "tight.brep"))
    assert main(["sections", str(tmp_path / "tight.brep"), "--layer", "5"]) == 0
    assert "tolerance" not in capsys.readouterr().err
    assert main(["sections", str(tmp_path / "loose.brep"), "--layer", "5"]) == 0
    assert ("warning: loose.brep: a vertex carries a tolerance of 0.5 mm"
            in capsys.readouterr().err)
