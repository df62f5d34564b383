"""Closing a document while one of its objects computes in a worker."""
from __future__ import annotations

from pathlib import Path

import pytest

from tests.gui.freecad_gui import run_gui_check

HERE = Path(__file__).resolve().parent

pytestmark = [pytest.mark.gui, pytest.mark.parts]


def test_closing_the_document_stops_the_worker_and_the_panel(tmp_path, parts_dir):
    run = run_gui_check(HERE / "checks" / "close_check.py", tmp_path,
                        {"part": str(parts_dir / "CrankArm.brep")})
    assert run["running_before"]
    assert run["questions"] and "save your changes" in run["questions"][0]
    assert "CloseMe" not in run["documents"]
    assert not run["dialog_open"] and not run["running_after"]
    assert run["status"] == "stopped: the document was closed"
    assert "Conformal: Sections stopped: CloseMe was closed" in run["report"]
    assert "Traceback" not in run["report"]
