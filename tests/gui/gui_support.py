"""Helpers for check scripts running inside the FreeCAD GUI (imported there, not by pytest)."""
from __future__ import annotations

import os

import FreeCAD
import FreeCADGui
from PySide import QtGui

#: Main window size for screenshots (fits the 1600x1000 Xvfb screen).
WINDOW_SIZE = (1400, 900)
#: Event-loop passes that let Qt lay out and paint after a change.
SETTLE_PASSES = 10


def settle() -> None:
    """Let Qt process pending layout and paint events."""
    for _ in range(SETTLE_PASSES):
        QtGui.QApplication.processEvents()


def prepare_main_window() -> None:
    """A fixed-size main window without the Start page, so screenshots are comparable."""
    window = FreeCADGui.getMainWindow()
    window.showNormal()
    window.resize(*WINDOW_SIZE)
    area = window.findChild(QtGui.QMdiArea)
    if area is not None:
        for sub in area.subWindowList():
            if "Start" in sub.windowTitle():
                sub.close()
    settle()


def grab_main_window(path: str) -> bool:
    """Screenshot of the main window as the screen shows it (QWidget.grab leaves the OpenGL
    3D view blank; a screen grab includes it)."""
    FreeCADGui.Selection.clearSelection()
    settle()
    window = FreeCADGui.getMainWindow()
    screen = QtGui.QApplication.primaryScreen()
    return bool(screen.grabWindow(window.winId()).save(path))


def grab_widget(widget, path: str) -> bool:
    """Screenshot of one Qt widget (no OpenGL inside)."""
    settle()
    return bool(widget.grab().save(path))


def save_3d_view(path: str, width: int = 1000, height: int = 750, fit: bool = True) -> None:
    """Offscreen render of the active 3D view on a white background."""
    FreeCADGui.Selection.clearSelection()    # no selection highlight in pictures
    view = FreeCADGui.ActiveDocument.ActiveView
    # Pending layout first, and the fit again once painted: a fit made while the view was
    # still being resized framed the nut in a corner of its picture (FreeCAD 1.0, once).
    settle()
    if fit:
        view.viewIsometric()
        view.fitAll()
        settle()
        view.fitAll()
    view.saveImage(path, width, height, "White")


def artifact(params: dict, name: str) -> str:
    """Path of an artefact file in the folder the test asked for."""
    folder = params["artifacts"]
    os.makedirs(folder, exist_ok=True)
    return os.path.join(folder, name)


def _report_view():
    window = FreeCADGui.getMainWindow()
    for edit in window.findChildren(QtGui.QTextEdit):
        if edit.objectName() == "Report view" or "Report" in (edit.parent().objectName() or ""):
            return edit
    return None


def report_view_text() -> str:
    """Everything the report view shows (errors of document objects land there); messages
    arrive through the event loop, so let it run first."""
    settle()
    edit = _report_view()
    return edit.toPlainText() if edit is not None else ""


def clear_report_view() -> None:
    """Empty the report view (before a screenshot, once its text has been checked)."""
    settle()
    edit = _report_view()
    if edit is not None:
        edit.clear()


def version() -> list:
    return FreeCAD.Version()[:3]
