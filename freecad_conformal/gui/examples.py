"""The published feature examples in a new document, computed one after another in worker
processes (gui/worker.py) so the window stays live, with a progress dialog that can cancel.

A feature whose worker fails keeps its error on the object (red in the tree, one line in
the report view); the others still run. Cancel stops the running worker; features not yet
computed stay touched, so a later recompute (Ctrl+R) computes them in place.
"""
from __future__ import annotations

import FreeCAD
import FreeCADGui

from freecad_conformal.gui.qt import QtCore, QtWidgets, translate
from freecad_conformal.gui.views import show

#: How often the runner looks at its worker (ms).
POLL_MS = 100
#: The runner started last (scripts and tests wait on it).
ACTIVE: dict = {}


def _tr(text: str) -> str:
    return translate("Conformal", text)


class BackgroundRecompute:
    """Compute `objects` (Computed proxies) in turn in workers; `done` when all have run."""

    def __init__(self, objects: list, title: str) -> None:
        self.pending = list(objects)
        self.total = len(objects)
        self.worker = None
        self.current = None
        self.inputs: dict = {}
        self.cancelled = False
        self.results: dict[str, bool] = {}
        self.dialog = QtWidgets.QProgressDialog(title, _tr("Cancel"), 0, self.total,
                                                FreeCADGui.getMainWindow())
        self.dialog.setWindowTitle(_tr("Conformal"))
        self.dialog.setWindowModality(QtCore.Qt.WindowModality.NonModal)
        self.dialog.setMinimumDuration(0)
        self.dialog.canceled.connect(self.cancel)
        self.timer = QtCore.QTimer()
        self.timer.setInterval(POLL_MS)
        self.timer.timeout.connect(self.poll)

    @property
    def done(self) -> bool:
        return self.worker is None and (self.cancelled or not self.pending)

    def start(self) -> "BackgroundRecompute":
        self._next()
        self.timer.start()
        return self

    def _next(self) -> None:
        from freecad_conformal.errors import ConformalError
        from freecad_conformal.gui.worker import WorkerProcess

        while self.pending and not self.cancelled:
            self.current = self.pending.pop(0)
            self.dialog.setValue(self.total - len(self.pending) - 1)
            self.dialog.setLabelText(f"{self.current.Label}")
            try:
                self.inputs = self.current.Proxy.inputs(self.current)
            except ConformalError:
                self._recompute()          # the object reports its own error
                continue
            self.worker = WorkerProcess(self.current.Proxy.TASK, self.inputs).start()
            return
        self._finish()

    def poll(self) -> None:
        if self.worker is None:
            return
        if not _alive(self.current):
            FreeCAD.Console.PrintMessage("Conformal examples stopped: the document was closed\n")
            self.cancel()
            return
        outcome = self.worker.poll()
        if outcome is None:
            return
        from freecad_conformal.objects.computed import precompute

        self.worker = None
        if outcome.traceback:
            FreeCAD.Console.PrintLog(f"Conformal worker:\n{outcome.traceback}\n")
        precompute(self.current, self.inputs, outcome.as_precomputed())
        self._recompute()
        self._next()

    def _recompute(self) -> None:
        self.current.touch()
        self.current.recompute()
        self.results[self.current.Label] = bool(self.current.isValid())

    def cancel(self) -> None:
        self.cancelled = True
        if self.worker is not None:
            self.worker.cancel()
            self.worker = None
        self._finish()

    def _finish(self) -> None:
        self.timer.stop()
        self.dialog.reset()
        self.dialog.hide()
        failed = [label for label, ok in self.results.items() if not ok]
        word = _tr("cancelled") if self.cancelled else _tr("done")
        FreeCAD.Console.PrintMessage(
            f"Conformal examples {word}: {sum(self.results.values())} of {self.total} features "
            f"computed{'; failed: ' + ', '.join(failed) if failed else ''}\n")

    def wait(self, timeout: float = 600.0) -> bool:
        """Keep the GUI going until every object ran (scripts and tests); True if all ran."""
        import time
        end = time.monotonic() + timeout
        while not self.done and time.monotonic() < end:
            QtWidgets.QApplication.processEvents()
            time.sleep(0.02)
        return self.done and all(self.results.values()) and len(self.results) == self.total


def _alive(obj) -> bool:
    try:
        return obj.Document.getObject(obj.Name) is not None \
            and obj.Document.Name in FreeCAD.listDocuments()
    except (RuntimeError, ReferenceError):      # the object's C++ side is gone
        return False


def open_examples() -> BackgroundRecompute:
    """A new document holding the published examples, their features computed in the
    background; returns the runner (ACTIVE["runner"] too)."""
    from freecad_conformal.objects.feature_examples import create_examples

    doc = FreeCAD.newDocument("FeatureExamples")
    made = create_examples(doc)
    for part, feature in made:
        show(feature)
        part.ViewObject.Transparency = 40     # the feature's paths show through the part
    FreeCADGui.SendMsgToActiveView("ViewFit")
    FreeCADGui.ActiveDocument.ActiveView.viewIsometric()
    runner = BackgroundRecompute([feature for _, feature in made],
                                 _tr("Computing the published feature examples")).start()
    ACTIVE["runner"] = runner
    return runner
