"""Recomputes the GUI did not start itself — a value changed in the property editor, Ctrl+R,
a reopened file — computed in worker processes (gui/worker.py) instead of the GUI thread.

objects/computed.py asks `defer(obj, task, inputs)` before computing in place. Here the
object's computation starts in a worker and the object keeps its last result; when the worker
ends, its outcome is handed in (`precompute`) and the object recomputed, which applies it (and
recomputes what depends on it). A newer change of the same object replaces a running worker;
closing the document or deleting the object ends it. Progress shows in the status bar.

Off (preference "Recompute in the background", or `computed.synchronous()` around a script's
recompute): recomputes compute in place, as FreeCAD does by itself.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import FreeCAD
import FreeCADGui

from freecad_conformal.gui.qt import QtCore

#: How often running workers are looked at (ms).
POLL_MS = 150


@dataclass
class _Job:
    document: str
    name: str
    label: str
    inputs: dict
    worker: object
    started: float = field(default_factory=time.monotonic)
    #: The finished worker's outcome with its shapes read, applied on the next turn.
    ready: dict | None = None


_RUNNING: dict[tuple[str, str], _Job] = {}
_TIMER: list = []


def enabled() -> bool:
    from freecad_conformal.gui.preferences import background_recompute

    return background_recompute()


def install() -> None:
    """Hand objects/computed.py the GUI's background recompute (FreeCAD's GUI start-up)."""
    from freecad_conformal.objects import computed

    computed.DEFER[0] = defer


def running() -> list[str]:
    """Labels of the objects computing in the background (status, tests)."""
    return [job.label for job in _RUNNING.values()]


def defer(obj, task: str, inputs: dict) -> bool:
    """Start (or keep) computing `obj` in a worker; False: compute in place instead."""
    from freecad_conformal.gui import task_panel
    from freecad_conformal.gui.worker import WorkerProcess
    from freecad_conformal.objects.computed import fingerprint

    if not enabled() or not task_panel.BACKGROUND["enabled"]:
        return False
    key = (obj.Document.Name, obj.Name)
    job = _RUNNING.get(key)
    if job is not None:
        if fingerprint(job.inputs) == fingerprint(inputs):
            return True                         # already on its way
        job.worker.cancel()                     # a newer change replaces it
    worker = WorkerProcess(task, inputs).start()
    _RUNNING[key] = _Job(obj.Document.Name, obj.Name, obj.Label, inputs, worker)
    _timer().start()
    _status(f"Conformal: computing {obj.Label} in the background")
    return True


def cancel_all() -> None:
    for job in _RUNNING.values():
        job.worker.cancel()
    _RUNNING.clear()


def wait(timeout: float = 600.0) -> bool:
    """Keep the GUI going until no background computation runs (scripts and tests)."""
    from freecad_conformal.gui.qt import QtWidgets

    end = time.monotonic() + timeout
    while _RUNNING and time.monotonic() < end:
        QtWidgets.QApplication.processEvents()
        time.sleep(0.02)
    return not _RUNNING


def _timer():
    if not _TIMER:
        timer = QtCore.QTimer()
        timer.setInterval(POLL_MS)
        timer.timeout.connect(_poll)
        _TIMER.append(timer)
    return _TIMER[0]


def _poll() -> None:
    """Look at each running worker. A finished one's shapes are read in this turn of the
    event loop and its result applied in the next: the two together held the window for
    0.5 s on a 1,440-layer section of CrankArm (0.1 s reading 14,000 edges, 0.3 s drawing
    them), each alone for at most the larger."""
    from freecad_conformal.objects.computed import precompute, read_shapes

    for key, job in list(_RUNNING.items()):
        document = FreeCAD.listDocuments().get(job.document)
        obj = document.getObject(job.name) if document is not None else None
        if obj is None:                         # closed or deleted meanwhile
            job.worker.cancel()
            del _RUNNING[key]
            continue
        if job.ready is not None:
            del _RUNNING[key]
            precompute(obj, job.inputs, job.ready)
            obj.touch()
            document.recompute()                # applies it, then what depends on it
            _status(f"Conformal: {job.label} {'done' if obj.isValid() else 'failed'}")
            continue
        outcome = job.worker.poll()
        if outcome is None:
            fraction, text = job.worker.progress()
            _status(f"Conformal: {job.label}: {text or 'computing'} "
                    f"({time.monotonic() - job.started:.0f} s)")
            continue
        if outcome.traceback:
            FreeCAD.Console.PrintLog(f"Conformal worker:\n{outcome.traceback}\n")
        job.ready = outcome.as_precomputed()
        if outcome.ok:
            job.ready["result"] = read_shapes(outcome.result)
        QtCore.QTimer.singleShot(0, _poll)      # apply once the window has had its turn
    if not _RUNNING:
        _timer().stop()


def _status(text: str) -> None:
    window = FreeCADGui.getMainWindow()
    if window is not None:
        window.statusBar().showMessage(text, 4000)
