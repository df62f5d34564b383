"""In the FreeCAD GUI: a plan on CrankArm runs in a worker process while a 100 ms timer in
the GUI thread keeps ticking; Cancel ends it; panels show the fields of the chosen mode."""
from __future__ import annotations

from pathlib import Path

import pytest

from tests.gui.freecad_gui import assert_image_has_content, run_gui_check

HERE = Path(__file__).resolve().parent
#: CrankArm at 1 mm layers plans in about 40 s here; the GUI start and the rest add a minute.
TIMEOUT_S = 400.0

pytestmark = [pytest.mark.gui, pytest.mark.parts, pytest.mark.slow]


@pytest.fixture(scope="module")
def run(tmp_path_factory, artifacts_dir, parts_dir) -> dict:
    tmp = tmp_path_factory.mktemp("worker")
    result = run_gui_check(HERE / "checks" / "worker_check.py", tmp,
                           {"artifacts": str(artifacts_dir), "parts": str(parts_dir),
                            "layer": 1.0, "timeout": TIMEOUT_S - 120}, timeout=TIMEOUT_S)
    print("plan in the worker:", result["plan"])
    return result


def test_gui_thread_keeps_ticking_during_a_plan(run):
    plan = run["plan"]
    assert run["worker_started"] and plan["valid"], plan["status"]
    assert plan["points"] > 1000 and plan["subparts"] >= 1
    assert plan["seconds"] > 3.0            # long enough for the measure to mean something
    # while the worker plans, the GUI thread is free; applying the 80,000 poses at the end
    # (storing, drawing) is one short stop in the GUI thread
    assert plan["max_gap_while_working"] < 0.5, plan
    assert plan["apply_s"] < 3.0, plan
    assert plan["ticks"] > 0.8 * plan["seconds"] / 0.1
    assert run["undo_names"] == ["Conformal Plan"]       # one undo step
    assert run["progress_text"] and "(" in run["progress_text"]


def test_cancel_ends_the_worker_and_removes_the_object(run):
    cancel = run["cancel"]
    assert cancel["process_gone"] and cancel["object_removed"]
    assert cancel["seconds"] < 5.0


def test_commands_take_solids_and_faces_of_their_kind(run):
    assert not run["plan_active_nothing"] and run["plan_active_face_of_body"]
    assert run["feature_kind"] == "rods"      # a sphere's face starts as rods


def test_panels_show_the_fields_of_the_mode_and_kind(run):
    assert "LayerMin" not in run["job_fields_uniform"] and "MaxCusp" in run["job_fields_cusp"]
    assert run["icon_set"]
    fields = run["feature_fields"]
    assert "RodDiameter" in fields["rods"] and "RodDiameter" not in fields["shell"]
    assert "PatternText" in fields["pattern"] and "Channels" in fields["channels"]
    assert "AxisPoint" not in run["sections_planar"] and "LayerHeight" in run["sections_planar"]
    assert "AxisPoint" in run["sections_cylindrical"]
    assert "LayerHeight" not in run["sections_cylindrical"]


def test_screenshots_are_not_blank(run):
    assert run["frames"] == run["plan"]["subparts"] or run["frames"] >= 1
    for shot in (run["running_shot"], run["job_shot"], run["job_machine_shot"]):
        assert_image_has_content(Path(shot))
