"""The dock panel in the real FreeCAD GUI: tool library and DOE tabs, preference page."""
from __future__ import annotations

from pathlib import Path

import pytest

from tests.gui.freecad_gui import assert_image_has_content, run_gui_check

HERE = Path(__file__).resolve().parent
DATA = HERE.parent / "unit" / "data"


@pytest.fixture(scope="module")
def panel_run(tmp_path_factory, artifacts_dir) -> dict:
    tmp = tmp_path_factory.mktemp("panel")
    return run_gui_check(HERE / "checks" / "panel_check.py", tmp,
                         {"artifacts": str(artifacts_dir), "tmp": str(tmp), "data": str(DATA)})


@pytest.mark.gui
def test_tool_library_tab_edits_persist(panel_run):
    tools = panel_run["tools"]
    assert tools["listed"] == tools["library"] >= 6
    assert tools["apply_ok"] and tools["saved_tilt"] == pytest.approx(45.0)
    assert not tools["bad_apply_ok"] and "diameter" in tools["bad_message"]
    assert tools["duplicate_ok"] and tools["after_duplicate"] == "uv_small_copy"
    assert tools["delete_ok"]
    assert "uv_small_copy" not in tools["exported_ids"] and "uv_small" in tools["exported_ids"]


@pytest.mark.gui
def test_doe_tab_reproduces_the_methods_study_and_applies_it(panel_run, tmp_path):
    doe = panel_run["doe"]
    assert doe["generate_ok"] and doe["typed_analyse_ok"]
    assert doe["typed_effects"]["A"] == pytest.approx(4.0)
    assert doe["typed_effects"]["B"] == pytest.approx(-2.0)
    assert doe["load_ok"] and doe["import_ok"] and doe["analyse_ok"], doe["message"]
    assert doe["effect_rows"] == 7           # 2^(4-1): seven alias classes
    assert doe["predicted_real"] == pytest.approx(2.53, abs=0.005)
    assert doe["plot_axes"] == 2             # mean and ln s² panels
    assert "optimum" in doe["report"].lower()
    assert doe["apply_ok"] and "uv_small" in doe["apply_message"]


@pytest.mark.gui
def test_preference_page_round_trip(panel_run):
    prefs = panel_run["preferences"]
    assert "rotary_mandrel" in prefs["machines"]
    assert prefs["before"] == "trunnion_ac" and prefs["after"] == "rotary_mandrel"
    assert prefs["chord"] == pytest.approx(0.005)


@pytest.mark.gui
def test_panel_screenshots_are_not_blank(panel_run):
    for shot in (panel_run["tools"]["shot"], panel_run["doe"]["shot"], panel_run["window_shot"]):
        assert_image_has_content(Path(shot))
