"""Every command of the workbench run programmatically on a real part in the FreeCAD GUI."""
from __future__ import annotations

from pathlib import Path

import pytest

from tests.gui.freecad_gui import assert_image_has_content, run_gui_check

HERE = Path(__file__).resolve().parent


@pytest.fixture(scope="module")
def commands_run(tmp_path_factory, artifacts_dir, parts_dir) -> dict:
    tmp = tmp_path_factory.mktemp("commands")
    return run_gui_check(HERE / "checks" / "commands_check.py", tmp,
                         {"artifacts": str(artifacts_dir), "tmp": str(tmp),
                          "parts": str(parts_dir)})


pytestmark = [pytest.mark.gui, pytest.mark.parts]


def test_analyse_shows_axis_breaks_and_splitting_faces(commands_run):
    analysis = commands_run["analysis"]
    assert analysis["ok"], analysis["message"]
    assert analysis["points"] > 10 and analysis["breaks"] >= 1 and analysis["faces"] >= 1


def test_commands_are_undoable_and_cancel_removes(commands_run):
    assert commands_run["undo_mode"] == 1
    assert commands_run["undo_removes"] and commands_run["redo_restores"]
    assert commands_run["cancel_removes"]


def test_decompose_colours_each_subpart(commands_run):
    decomposition = commands_run["decomposition"]
    assert decomposition["ok"], decomposition["message"]
    # the table's top overhangs its legs: at least two sub-parts, each its own colour
    assert decomposition["subparts"] >= 2
    assert decomposition["subparts"] == len(decomposition["order"]) == decomposition["colours"]


def test_sections_plan_post_verify_feature_chain(commands_run):
    assert commands_run["sections"]["ok"] and commands_run["sections"]["layers"] == 12
    job = commands_run["job"]
    assert job["ok"], job["message"]
    assert job["points"] > 1000 and job["machine"] == "trunnion_ac"
    # The table turned over needs no support (its top's edge round is laid on the bed):
    # the Job builds it in one piece, where the Decomposition shows its top and four legs.
    assert job["subparts"] == 1 and commands_run["decomposition"]["subparts"] == 5
    post = commands_run["post"]
    assert post["ok"] and post["blocks"] > 100, post["message"]
    assert commands_run["feature_post"]["blocks"] > 10, commands_run["feature_post"]["message"]
    verify = commands_run["verify"]
    assert verify["ok"] and verify["passed"], verify["report"]
    assert verify["position"] < 0.01
    feature = commands_run["feature"]
    assert feature["ok"] and feature["points"] > 10, feature["message"]


def test_stream_needs_pyserial_and_reports_a_missing_port(commands_run):
    assert commands_run["stream_active"] == commands_run["pyserial"]
    if commands_run["pyserial"]:
        assert not commands_run["stream_bad_baud_started"]
        assert "speed (baud) (--baud) must be a number, got 'fast'" in \
            commands_run["stream_bad_baud_message"]
        assert "no-such-port" in commands_run["stream_message"]
        assert "does not exist" in commands_run["stream_message"]


def test_bad_parameter_marks_the_job_and_recovers(commands_run):
    assert not commands_run["bad_job_valid"] and commands_run["fixed_job_valid"]
    assert "Conformal: Job failed" in commands_run["report"]


def test_everything_reopens_and_recomputes(commands_run):
    reopen = commands_run["reopen"]
    assert reopen["same_objects"] and reopen["invalid"] == []
    assert reopen["subparts"] == commands_run["decomposition"]["subparts"]
    assert reopen["verify_passed"]


def test_command_screenshots_are_not_blank(commands_run):
    for shot in (commands_run["analysis"]["shot"], commands_run["decomposition"]["shot"],
                 commands_run["job"]["shot"], commands_run["plan_panel_shot"]):
        assert_image_has_content(Path(shot))


def test_a_derived_speed_reads_as_derived_not_zero(commands_run):
    # An optional speed left to the material shows empty with what it stands for, not as
    # "0.00 mm/s"; typed, it holds the value; emptied by the user, it is derived again.
    unset, typed, emptied = (commands_run["derived_speed"][k] for k in ("unset", "typed", "emptied"))
    text, placeholder, value = unset
    assert text == "" and "material" in placeholder and value == 0.0
    assert typed[0].startswith("35") and typed[1] == 35.0
    assert emptied == ["", 0.0]
