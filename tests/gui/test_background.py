"""Recomputes the GUI did not start (property editor, Ctrl+R, a reopened file) run in a
worker process: the window stays live and the result arrives."""
from __future__ import annotations

from pathlib import Path

import pytest

from tests.gui.freecad_gui import run_gui_check

HERE = Path(__file__).resolve().parent

pytestmark = [pytest.mark.gui, pytest.mark.parts]


@pytest.fixture(scope="module")
def run(tmp_path_factory, parts_dir) -> dict:
    tmp = tmp_path_factory.mktemp("background")
    return run_gui_check(HERE / "checks" / "background_check.py", tmp,
                         {"part": str(parts_dir / "CrankArm.brep"), "tmp": str(tmp),
                          "background_recompute": True, "timeout": 120}, timeout=240)


def test_a_property_change_recomputes_in_a_worker(run):
    assert run["hooked"] and run["first_layers"] > 10
    assert run["recompute_s"] < 1.0, run                 # returned at once
    assert run["running"] and run["layers_meanwhile"] == run["first_layers"]
    assert run["finished"] and run["valid"]
    assert run["layers_after"] > 20 * run["first_layers"]   # 0.05 mm, the last change
    assert run["seconds"] > 1.0 and run["max_gap"] < 0.5, run


def test_a_reopened_file_recomputes_in_a_worker_too(run):
    assert run["reopened_recompute_s"] < 1.0, run
    assert run["reopened_finished"] and run["reopened_layers"] > run["first_layers"]
