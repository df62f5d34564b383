"""In FreeCAD: the "Published feature examples" command builds every case as a part with a
Feature object, computes them in workers while a 100 ms QTimer keeps ticking, and Cancel on
a second run stops with nothing left running."""
import time

import FreeCAD
import FreeCADGui
from freecad_conformal.gui.qt import QtCore, QtWidgets

import gui_support


def main(params: dict) -> dict:
    gui_support.prepare_main_window()
    FreeCADGui.activateWorkbench("ConformalWorkbench")
    from freecad_conformal.gui.examples import ACTIVE
    from freecad_conformal.jobs.feature_examples import CASES

    ticks: list[float] = []
    timer = QtCore.QTimer()
    timer.setInterval(100)
    timer.timeout.connect(lambda: ticks.append(time.monotonic()))
    timer.start()
    started = time.monotonic()
    FreeCADGui.runCommand("Conformal_FeatureExamples")
    runner = ACTIVE["runner"]
    all_ran = runner.wait(params["timeout"])
    seconds = time.monotonic() - started
    timer.stop()
    doc = FreeCAD.ActiveDocument
    features = [o for o in doc.Objects if "Kind" in o.PropertiesList]
    out = {
        "cases": [c.name for c in CASES],
        "all_ran": all_ran,
        "seconds": seconds,
        "max_gap": max((b - a for a, b in zip(ticks, ticks[1:])), default=99.0),
        "features": {f.Label: {"valid": bool(f.isValid()), "kind": f.Kind,
                               "points": f.PointCount, "length": f.PathLength.Value,
                               "part": f.Source[0].Label, "face": f.Source[1][0],
                               "provider": type(getattr(f.ViewObject, "Proxy", None)).__name__}
                     for f in features},
        "parts": [o.Label for o in doc.Objects if o.TypeId == "Part::Feature"],
    }
    gui_support.settle()
    view_png = gui_support.artifact(params, "feature_examples_view.png")
    gui_support.save_3d_view(view_png)
    out["screenshot"] = view_png

    # a second run, cancelled at once: the running worker ends and the rest stay uncomputed
    FreeCADGui.runCommand("Conformal_FeatureExamples")
    second = ACTIVE["runner"]
    second.dialog.findChild(QtWidgets.QPushButton).click()     # as a user would
    gui_support.settle()
    out["cancel"] = {"done": second.done, "cancelled": second.cancelled,
                     "worker": second.worker is not None, "computed": len(second.results),
                     "dialog_visible": second.dialog.isVisible()}
    return out
