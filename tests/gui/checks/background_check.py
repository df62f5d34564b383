"""In FreeCAD: a Sections object changed as from the property editor (a new layer height,
then Ctrl+R's doc.recompute()): the recompute returns at once, a 100 ms timer keeps ticking
while a worker computes, and the result is applied when it ends; a change while it runs
replaces the running computation; reopening the saved file and recomputing does the same."""
import os
import time

import FreeCAD
import FreeCADGui
import Part

import gui_support
from freecad_conformal.gui.qt import QtCore


def _ticking():
    ticks = []
    timer = QtCore.QTimer()
    timer.setInterval(100)
    timer.timeout.connect(lambda: ticks.append(time.monotonic()))
    timer.start()
    return timer, ticks


def _spin(seconds: float) -> None:
    """Let the event loop run for `seconds`, as it does while a user edits a property (a
    sleep here would stop the very ticks the check counts)."""
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        QtCore.QCoreApplication.processEvents()
        time.sleep(0.01)


def _turns_timed(background) -> list:
    """(start, end) of each turn of the background poll: the last is the one that applied
    the finished result."""
    turns = []
    poll = background._poll

    def timed() -> None:
        start = time.monotonic()
        poll()
        turns.append((start, time.monotonic()))

    background._poll = timed        # the apply turn is a singleShot of the module's _poll
    return turns


def main(params: dict) -> dict:
    gui_support.prepare_main_window()
    FreeCADGui.activateWorkbench("ConformalWorkbench")
    from freecad_conformal.gui import background
    from freecad_conformal.gui.views import show
    from freecad_conformal.objects.computed import synchronous
    from freecad_conformal.objects.sections_feature import create_sections

    doc = FreeCAD.newDocument("Background")
    Part.insert(params["part"], doc.Name)
    body = doc.Objects[0]
    sections = show(create_sections(doc, body))
    sections.LayerHeight = 5.0
    with synchronous():
        doc.recompute()
    out = {"first_layers": sections.LayerCount, "hooked": background.enabled()}

    applying = _turns_timed(background)
    timer, ticks = _ticking()
    sections.LayerHeight = 0.1                   # as the property editor would set it
    began = time.monotonic()
    doc.recompute()
    out["recompute_s"] = time.monotonic() - began
    out["running"] = background.running()
    out["layers_meanwhile"] = sections.LayerCount
    _spin(0.3)
    sections.LayerHeight = 0.05                  # changed again while it computes
    doc.recompute()
    out["finished"] = background.wait(params["timeout"])
    out["seconds"] = time.monotonic() - began
    timer.stop()
    gaps = [(b - a, a - began) for a, b in zip(ticks, ticks[1:])]
    out["max_gap"], out["max_gap_at"] = max(gaps, default=(99.0, 0.0))
    # The last turn applies the result: FreeCAD draws the new shape there, so that gap is
    # held to FreeCAD's own drawing of it (the same shape set again, below).
    last_start, last_end = applying[-1] if applying else (0.0, 0.0)
    out["max_gap_computing"] = max((b - a for a, b in zip(ticks, ticks[1:])
                                    if b <= last_start or a >= last_end), default=99.0)
    out["max_gap_applying"] = max((b - a for a, b in zip(ticks, ticks[1:])
                                   if a < last_end and b > last_start), default=0.0)
    out["layers_after"] = sections.LayerCount
    out["valid"] = bool(sections.isValid())
    again = sections.Shape.copy()
    FreeCADGui.updateGui()
    shown = time.monotonic()
    sections.Shape = again                      # drawn again by its own view provider
    FreeCADGui.updateGui()
    out["drawing_s"] = time.monotonic() - shown

    name = sections.Name
    path = os.path.join(params["tmp"], "background.FCStd")
    doc.saveAs(path)
    FreeCAD.closeDocument(doc.Name)
    reopened = FreeCAD.openDocument(path)
    again = reopened.getObject(name)
    again.LayerHeight = 1.0
    began = time.monotonic()
    reopened.recompute()
    out["reopened_recompute_s"] = time.monotonic() - began
    out["reopened_finished"] = background.wait(params["timeout"])
    out["reopened_layers"] = again.LayerCount
    return out
