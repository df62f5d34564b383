"""Parametric document objects and the toolpath view in the real FreeCAD GUI."""
from __future__ import annotations

import math
from pathlib import Path

import pytest

from tests.gui.freecad_gui import assert_image_has_content, run_gui_check

HERE = Path(__file__).resolve().parent


@pytest.fixture(scope="module")
def objects_run(tmp_path_factory, artifacts_dir, parts_dir) -> dict:
    tmp = tmp_path_factory.mktemp("objects")
    return run_gui_check(HERE / "checks" / "objects_check.py", tmp,
                         {"artifacts": str(artifacts_dir), "tmp": str(tmp),
                          "parts": str(parts_dir)})


def cylinder_in_sphere_area(sphere_radius: float, radii: list[float]) -> float:
    """Lateral area of each cylinder r inside a sphere R about its axis: 2πr · 2√(R² − r²)."""
    return sum(2 * math.pi * r * 2 * math.sqrt(sphere_radius ** 2 - r ** 2) for r in radii)


@pytest.mark.gui
@pytest.mark.parts
def test_sections_recompute_on_parameter_and_body_changes(objects_run):
    sections = objects_run["sections"]
    assert sections["nut_valid"]
    assert sections["nut_layers_2mm"] > 2 * sections["nut_layers_5mm"] > 0
    assert sections["nut_wires"] >= sections["nut_layers_2mm"]
    radii = [2.0, 4.0, 6.0, 8.0]
    assert sections["ball_area_r10"] == pytest.approx(cylinder_in_sphere_area(10.0, radii), rel=1e-6)
    assert sections["ball_area_r9"] == pytest.approx(cylinder_in_sphere_area(9.0, radii), rel=1e-6)


@pytest.mark.gui
@pytest.mark.parts
def test_failing_parameter_marks_the_object(objects_run):
    sections = objects_run["sections"]
    assert not sections["bad_valid"]
    assert "Invalid" in sections["bad_state"] or "Error" in " ".join(sections["bad_state"])
    assert ("Conformal: BadSections failed: layer height (--layer-height / LayerHeight) must be "
            "> 0 mm, got 0 mm") in sections["report"]


@pytest.mark.gui
@pytest.mark.parts
def test_hundred_thousand_poses_are_one_line_set(objects_run):
    toolpath = objects_run["toolpath"]
    assert toolpath["points"] == 100_000
    assert toolpath["stats"]["vertices"] == 100_000 and toolpath["stats"]["moves"] == 99_999
    assert toolpath["nodes"]["IndexedLineSet"] == 1
    assert toolpath["nodes"]["Coordinate3"] == 3          # path + axis ticks + platform
    # every tenth segment (1000 poses) is travel: hidden, 10 x 1000 moves fewer
    assert toolpath["moves_without_travel"] == 99_999 - 10 * 1000
    assert toolpath["axis_ticks"] == 50
    print(f"100k poses drawn in {toolpath['seconds_100k']:.2f} s")


@pytest.mark.gui
@pytest.mark.parts
def test_job_plans_the_bracket_with_its_subparts(objects_run):
    job = objects_run["job"]
    assert job["valid"] and job["points"] > 1000
    assert job["subparts"] == 2 and job["distinct_segment_subparts"] == [0, 1]
    assert "sub-part" in job["summary"]
    # The property editor shows the summary on one line: the Report view has it whole.
    assert "Conformal: BracketJob:" in job["report_view"]
    assert all(line in job["report_view"] for line in job["summary"].splitlines() if line)
    assert "G1" in job["gcode_head"] or "G0" in job["gcode_head"]


@pytest.mark.gui
@pytest.mark.parts
def test_save_close_reopen_recompute(objects_run):
    reopen = objects_run["reopen"]
    assert reopen["after_open"] == reopen["before"]
    assert reopen["after_recompute"] == reopen["before"]
    assert reopen["invalid_after_recompute"] == []
    assert reopen["helix_file_exists"] and reopen["helix_drawn"]["vertices"] == 100_000
    assert reopen["proxy_classes"]["BracketJob"] == "JobFeature"
    assert "failed" not in objects_run["report_at_end"]


@pytest.mark.gui
@pytest.mark.parts
def test_object_screenshots_are_not_blank(objects_run):
    for shot in (objects_run["sections"]["shot"], objects_run["toolpath"]["shot"],
                 objects_run["job"]["shot"], objects_run["job"]["window_shot"]):
        assert_image_has_content(Path(shot))
