"""`freecadcmd -t TestConformalApp` (FreeCAD's own test runner) passes with the addon installed."""
from __future__ import annotations

import re

from tests.gui.freecad_gui import run_freecadcmd


def test_freecad_runs_the_conformal_test_module(tmp_path):
    code, log = run_freecadcmd(["-t", "TestConformalApp"], tmp_path)
    assert code == 0, log[-4000:]
    ran = re.search(r"Ran (\d+) tests? in", log)
    assert ran, log[-4000:]
    assert int(ran.group(1)) >= 7
    assert re.search(r"^OK\b", log, re.MULTILINE), log[-4000:]
    # The module ran from the addon folder FreeCAD found in the user home.
    assert "test_sphere_section_is_a_disc" in log
