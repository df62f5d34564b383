"""Executed by the FreeCAD GUI (`freecad gui_runner.py`): runs one check script, reports JSON.

Environment (set by freecad_gui.run_gui_check): CONFORMAL_GUI_CHECK (script defining
main(params) -> dict), CONFORMAL_GUI_RESULT (JSON path), CONFORMAL_GUI_PARAMS (JSON object),
CONFORMAL_GUI_SUPPORT (folder of gui_support.py), CONFORMAL_GUI_STACKS and
CONFORMAL_GUI_WATCHDOG (where and when to dump the Python stacks of a hung check). The check runs once the event loop is up;
the process then ends at once (os._exit) so no "save changes?" dialog can hold it.
"""
import faulthandler
import json
import os
import runpy
import sys
import traceback

from PySide import QtCore


def _run_check() -> None:
    result = {}
    try:
        sys.path.insert(0, os.environ["CONFORMAL_GUI_SUPPORT"])
        sys.path.insert(0, os.path.dirname(os.environ["CONFORMAL_GUI_CHECK"]))
        params = json.loads(os.environ.get("CONFORMAL_GUI_PARAMS") or "{}")
        # checks read results right after doc.recompute(): computed in place unless a check
        # is about the background recompute itself
        import FreeCAD
        FreeCAD.ParamGet("User parameter:BaseApp/Preferences/Mod/Conformal").SetBool(
            "RecomputeInBackground", bool(params.get("background_recompute")))
        main = runpy.run_path(os.environ["CONFORMAL_GUI_CHECK"])["main"]
        result = main(params)
    except BaseException:  # noqa: B036 - every failure must reach the JSON, then we exit
        result = dict(result or {}, error=traceback.format_exc())
    with open(os.environ["CONFORMAL_GUI_RESULT"], "w", encoding="utf-8") as handle:
        json.dump(result, handle, indent=1, default=str)
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(0)


# A hung check (a modal dialog, a deadlock) shows where it hangs: Python's stacks go to the
# log shortly before the test's timeout kills FreeCAD.
# (FreeCAD's redirected stderr has no file descriptor, so the stacks go to their own file.)
_STACKS = open(os.environ["CONFORMAL_GUI_STACKS"], "w", encoding="utf-8")  # noqa: SIM115
faulthandler.dump_traceback_later(float(os.environ.get("CONFORMAL_GUI_WATCHDOG", "120")),
                                  exit=False, file=_STACKS)
QtCore.QTimer.singleShot(0, _run_check)
