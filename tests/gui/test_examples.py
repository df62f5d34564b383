"""The published UV feature examples from the GUI: one command, every case computed in the
background as Feature objects a user can edit, and cancellable."""
from __future__ import annotations

from pathlib import Path

import pytest

from tests.gui.freecad_gui import assert_image_has_content, run_gui_check

HERE = Path(__file__).resolve().parent
TIMEOUT_S = 240.0

pytestmark = [pytest.mark.gui]


@pytest.fixture(scope="module")
def run(tmp_path_factory, artifacts_dir) -> dict:
    tmp = tmp_path_factory.mktemp("examples")
    return run_gui_check(HERE / "checks" / "examples_check.py", tmp,
                         {"artifacts": str(artifacts_dir), "timeout": TIMEOUT_S - 90},
                         timeout=TIMEOUT_S)


def test_every_published_case_becomes_a_computed_feature(run):
    assert run["all_ran"], run["features"]
    features = run["features"]
    assert sorted(f["part"] for f in features.values()) == sorted(run["cases"])
    assert sorted(run["parts"]) == sorted(run["cases"])
    for label, feature in features.items():
        assert feature["valid"] and feature["points"] > 4, (label, feature)
        assert feature["provider"] == "ViewProviderToolpath", label
    kinds = sorted(f["kind"] for f in features.values())
    assert kinds == ["channels", "pattern", "rods", "rods", "shell"]
    # the tilted rod: 12 mm of curing plus the approach, alone on its cap
    rod = next(f for f in features.values() if f["part"] == "12 mm tilted rod")
    assert 12.0 < rod["length"] < 40.0


def test_the_window_stays_live_while_examples_compute(run):
    assert run["seconds"] > 2.0
    assert run["max_gap"] < 1.0, run["max_gap"]


def test_cancel_stops_the_examples(run):
    cancel = run["cancel"]
    assert cancel["done"] and cancel["cancelled"] and not cancel["worker"], cancel
    assert cancel["computed"] < len(run["cases"])
    assert not cancel["dialog_visible"]


def test_examples_screenshot_is_not_blank(run):
    assert_image_has_content(Path(run["screenshot"]))
