"""The batch command end to end on tiny generated parts, with 1 and 2 local workers."""
from __future__ import annotations

import csv
import json

import pytest

from freecad_conformal.cli import main
from tests.geometry.batch_parts import EXPECTED_LAYERS, make_parts

GCODE_FILES = {"box.step": "box.gcode", "cyl.brep": "cyl.gcode",
               "two.FCStd#Left": "two_Left.gcode", "two.FCStd#Right": "two_Right.gcode"}


@pytest.fixture(scope="module")
def parts(tmp_path_factory):
    return make_parts(tmp_path_factory.mktemp("batch-parts"))


def _csv_rows(path):
    with open(path, newline="", encoding="utf-8") as handle:
        return list(csv.DictReader(handle))


@pytest.mark.slow
@pytest.mark.parametrize("workers", [1, 2])
def test_batch_plans_every_part_and_reports_the_broken_one(parts, tmp_path, capsys, workers):
    out = tmp_path / "out"
    inputs = [parts["box"], parts["cyl"], parts["two"], parts["broken"]]
    code = main(["batch", *map(str, inputs), "--layer", "1", "--bead-width", "1", "-o", str(out),
                 "--workers", str(workers)])
    assert code == 1  # one part failed
    assert "4 ok, 1 failed" in capsys.readouterr().out
    assert sorted(p.name for p in out.iterdir()) == sorted(
        [*GCODE_FILES.values(), "batch-report.csv", "batch-report.json"])

    rows = _csv_rows(out / "batch-report.csv")
    assert [row["part"] for row in rows] == [*GCODE_FILES, "broken.step"]  # input order
    for row in rows[:4]:
        assert row["status"] == "ok" and row["error"] == ""
        assert int(row["layers"]) == EXPECTED_LAYERS[row["part"]]
        assert int(row["subparts"]) == 1
        assert float(row["material_mm3"]) > 0 and float(row["time_s"]) > 0
        gcode = out / row["gcode"]
        assert row["gcode"] == GCODE_FILES[row["part"]]
        assert int(row["gcode_bytes"]) == gcode.stat().st_size
        assert "(machine: Table-table A/C trunnion [trunnion_ac])" in gcode.read_text()
    assert [row["body"] for row in rows] == ["", "", "Left", "Right", ""]
    broken = rows[4]
    assert broken["status"] == "failed" and broken["gcode"] == "" and broken["layers"] == ""
    assert broken["error"].startswith("cannot read broken.step")

    report = json.loads((out / "batch-report.json").read_text())
    assert report["summary"] == {"parts": 5, "ok": 4, "failed": 1}
    assert [p["part"] for p in report["parts"]] == [row["part"] for row in rows]
    assert report["parts"][0]["layers"] == 6 and report["parts"][4]["error"] == broken["error"]
    assert report["settings"]["options"]["layers"]["thickness"] == 1.0


@pytest.mark.slow
def test_batch_gcode_is_what_the_plan_command_writes(parts, tmp_path):
    """Same part, same options: the batch plans exactly as `plan` does."""
    assert main(["plan", str(parts["cyl"]), "--layer", "1", "--bead-width", "1",
                 "-o", str(tmp_path / "plan.gcode")]) == 0
    assert main(["batch", str(parts["cyl"]), "--layer", "1", "--bead-width", "1", "-o", str(tmp_path / "batch"),
                 "--workers", "0"]) == 0
    assert (tmp_path / "batch" / "cyl.gcode").read_text() == (tmp_path / "plan.gcode").read_text()


class _Recorder:
    """Stands in for progress.Progress: remembers its total and the steps."""

    def __init__(self, total):
        self.total, self.steps, self.closed = total, [], False

    def update(self, steps=1):
        self.steps.append(steps)

    def close(self):
        self.closed = True


def test_all_good_parts_exit_zero_and_progress_counts_every_part(parts, tmp_path):
    from freecad_conformal.jobs.batch.run import run_batch
    from freecad_conformal.commands.batch import plan_options

    bars = []

    def make_progress(total):
        bars.append(_Recorder(total))
        return bars[-1]

    args = _parse(["batch", "x", "-o", str(tmp_path), "--layer", "1", "--bead-width", "1"])
    result = run_batch([str(parts["box"]), str(parts["two"])], plan_options(args), tmp_path,
                       workers=0, make_progress=make_progress)
    assert result.failed == 0
    assert [row["part"] for row in result.rows] == ["box.step", "two.FCStd#Left", "two.FCStd#Right"]
    assert bars[0].total == 3 and sum(bars[0].steps) == 3 and bars[0].closed


def _parse(argv):
    from freecad_conformal.cli import build_parser

    return build_parser().parse_args(argv)


def test_options_follow_the_plan_command(tmp_path):
    from freecad_conformal.commands.batch import plan_options

    options = plan_options(_parse(["batch", "x", "-o", str(tmp_path), "--layer", "0.5",
                                   "--infill", "40", "--tool", "fdm_0p4", "--tilt"]))
    assert options.layers.thickness == 0.5 and options.layers.tilt is True
    assert options.paths.fill.density == pytest.approx(0.4)


def test_batch_offers_every_plan_setting_with_the_same_default(tmp_path):
    """When the plan command gains or renames a setting, batch must follow."""
    from freecad_conformal.commands.batch import BATCH_ONLY, PLAN_ONLY, PLAN_PER_FILE

    plan_defaults = vars(_parse(["plan", "part.step", "-o", "x.gcode"]))
    batch_defaults = vars(_parse(["batch", "part.step", "-o", str(tmp_path)]))
    dispatch = {"command", "_run"}  # the CLI's own entries
    shared = set(plan_defaults) - set(PLAN_PER_FILE) - set(PLAN_ONLY) - dispatch
    assert set(batch_defaults) - set(BATCH_ONLY) - dispatch == shared
    assert {k: batch_defaults[k] for k in shared} == {k: plan_defaults[k] for k in shared}


@pytest.mark.parametrize("arguments, message", [
    (["--tool", "no_such_tool"], "no tool 'no_such_tool' in the library"),
    (["--machine", "no_such_machine"], "unknown machine 'no_such_machine'"),
    (["--layer", "-1"], "layer height (--layer-height / LayerHeight) must be > 0 mm, got -1"),
    (["--workers", "-2"], "--workers must be 0 or more"),
    (["--suffix", "gcode"], "suffix must start with a dot"),
])
def test_bad_options_fail_the_batch_before_any_part(parts, tmp_path, capsys, arguments, message):
    out = tmp_path / "out"
    assert main(["batch", str(parts["box"]), "-o", str(out), *arguments]) == 1
    assert message in capsys.readouterr().err
    assert not out.exists()
