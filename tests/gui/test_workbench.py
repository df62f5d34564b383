"""Foundation acceptance: the addon installed in a FreeCAD user home registers the Conformal
workbench with its icon, and activating it in the real FreeCAD GUI (Xvfb) works."""
from __future__ import annotations

from pathlib import Path

import pytest

from tests.gui.freecad_gui import PROJECT_ROOT, assert_image_has_content, run_gui_check

CHECKS = Path(__file__).resolve().parent / "checks"


@pytest.fixture(scope="module")
def workbench_run(tmp_path_factory, artifacts_dir) -> dict:
    tmp = tmp_path_factory.mktemp("workbench")
    return run_gui_check(CHECKS / "workbench_check.py", tmp, {"artifacts": str(artifacts_dir)})


@pytest.mark.gui
def test_workbench_activates_from_the_user_mod_folder(workbench_run):
    assert workbench_run["active_workbench"] == "ConformalWorkbench"
    assert workbench_run["workbench_menu_text"] == "Conformal"
    # Loaded through <user home>/Mod/Conformal, i.e. installed as the Addon Manager would.
    assert Path(workbench_run["package_file"]).is_relative_to(PROJECT_ROOT)
    assert "freecad-home" in workbench_run["user_app_data"]


@pytest.mark.gui
def test_workbench_icon_is_the_shipped_svg(workbench_run):
    icon = Path(workbench_run["workbench_icon"])
    assert icon.is_file() and icon.suffix == ".svg"
    assert icon.resolve() == (PROJECT_ROOT / "resources" / "icons" / "Conformal.svg").resolve()


@pytest.mark.gui
def test_commands_fill_the_toolbar_and_menu(workbench_run):
    expected = workbench_run["expected_commands"]
    assert expected, "the workbench registers no command"
    assert set(expected) <= set(workbench_run["commands"])
    menu_texts = [workbench_run["commands"][name]["menuText"] for name in expected]
    assert workbench_run["toolbars"].get("Conformal") == menu_texts
    assert "&Conformal" in workbench_run["menus"] or "Conformal" in workbench_run["menus"]
    assert workbench_run["conformal_menu"] == menu_texts
    for name in expected:
        info = workbench_run["commands"][name]
        assert info["toolTip"], f"{name} has no tooltip"
        assert Path(info["pixmap"]).is_file(), f"{name} icon {info['pixmap']} is missing"


@pytest.mark.gui
def test_screenshots_show_the_window_and_the_part(workbench_run):
    shots = workbench_run["screenshots"]
    window = assert_image_has_content(Path(shots["window"]), min_width=1000, min_height=700)
    view = assert_image_has_content(Path(shots["view"]))
    assert (view["width"], view["height"]) == (1000, 750)
    assert window["colours"] > view["colours"] / 4
