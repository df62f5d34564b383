"""In FreeCAD: a Sections computation is running in its worker when the user closes the
document (window X, "Discard" in FreeCAD's question): the worker stops, the task panel
closes, and a line in the report view says why."""
import time

import FreeCAD
import FreeCADGui
import Part

import gui_support
from freecad_conformal.gui.qt import QtCore, QtWidgets


def _spin(seconds: float) -> None:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        QtWidgets.QApplication.processEvents()
        time.sleep(0.05)


def main(params: dict) -> dict:
    gui_support.prepare_main_window()
    FreeCADGui.activateWorkbench("ConformalWorkbench")
    from freecad_conformal.gui.task_panel import ACTIVE

    doc = FreeCAD.newDocument("CloseMe")
    Part.insert(params["part"], doc.Name)
    doc.recompute()
    FreeCADGui.Selection.addSelection(doc.Objects[0])
    FreeCADGui.runCommand("Conformal_Sections")
    gui_support.settle()
    panel = ACTIVE["panel"]
    panel.set_field("LayerHeight", 0.05)          # long enough to close the document meanwhile
    panel.accept()
    _spin(1.0)
    out = {"running_before": panel.worker is not None}
    questions = []

    def discard() -> None:                      # the user's answer to "save changes?"
        box = QtWidgets.QApplication.activeModalWidget()
        if box is None:
            return
        questions.append(getattr(box, "text", lambda: "")())
        for button in box.findChildren(QtWidgets.QAbstractButton):
            if button.text().replace("&", "") == "Discard":
                button.click()
                return

    timer = QtCore.QTimer()
    timer.timeout.connect(discard)
    timer.start(200)
    FreeCADGui.runCommand("Std_CloseActiveWindow")
    _spin(2.0)
    timer.stop()
    out.update(questions=questions, documents=list(FreeCAD.listDocuments()),
               dialog_open=bool(FreeCADGui.Control.activeDialog()),
               running_after=panel.worker is not None, status=panel.status,
               report=gui_support.report_view_text()[-2000:])
    return out
