"""The task panel of a new object: its parameters as the settings schema describes them, and
OK running the computation in a worker process while the GUI stays live.

Commands open it on the object they created inside an open document transaction. OK copies
the fields into the object, checks them (messages inline), then runs the object's computation
in a worker (gui/worker.py) with a progress line; when it ends the result is applied by one
recompute and the transaction is committed (one undo step). Cancel ends a running worker and
aborts the transaction, which removes the new object. A failure keeps the panel open with
its one-line message; the traceback goes to the log.
"""
from __future__ import annotations

import time
from typing import Sequence

import FreeCAD
import FreeCADGui

from freecad_conformal.gui import fields as F
from freecad_conformal.gui.panel_layout import field_specs, grouped
from freecad_conformal.gui.qt import QtCore, QtGui, QtWidgets, standard_buttons, translate
from freecad_conformal.gui.widgets import MessageLine

#: How often the panel looks at a running worker (ms): often enough for a live progress line.
POLL_MS = 100
#: The panel opened last (scripts and tests drive it).
ACTIVE: dict = {}
#: Off: compute in the GUI thread as a plain recompute (macros that want it synchronous).
BACKGROUND = {"enabled": True}


def _tr(text: str) -> str:
    return translate("Conformal", text)


class ObjectTaskPanel:
    """Fields for the editable parameters of `obj` in `groups`."""

    def __init__(self, obj, groups: Sequence[str], title: str, icon: str = "") -> None:
        self.obj = obj
        proxy = getattr(obj, "Proxy", None)
        self.task = getattr(proxy, "TASK", "") or ("feature" if "Kind" in obj.PropertiesList else "")
        self.settings = getattr(proxy, "SETTINGS", ())
        self.form = QtWidgets.QWidget()
        self.form.setWindowTitle(title)
        if icon:
            self.form.setWindowIcon(QtGui.QIcon(icon))
        outer = QtWidgets.QVBoxLayout(self.form)
        self.progress_bar = QtWidgets.QProgressBar()
        self.progress_bar.setVisible(False)
        self.progress_line = QtWidgets.QLabel()
        self.progress_line.setWordWrap(True)
        self.progress_line.setVisible(False)
        self.message = MessageLine()
        for widget in (self.progress_bar, self.progress_line, self.message):
            outer.addWidget(widget)
        properties = [(n, obj.getTypeIdOfProperty(n), obj.getGroupOfProperty(n),
                       obj.getDocumentationOfProperty(n))
                      for n in obj.PropertiesList if not obj.getEditorMode(n)]
        self.specs = {s.prop: s for s in field_specs(properties, self.settings, groups)}
        self.fields: dict[str, QtWidgets.QWidget] = {}
        self.rows: dict[str, tuple[QtWidgets.QWidget, QtWidgets.QWidget]] = {}
        self.boxes: list[tuple[QtWidgets.QGroupBox, list[str]]] = []
        for group, specs in grouped(list(self.specs.values())):
            box = QtWidgets.QGroupBox(_tr(group))
            layout = QtWidgets.QFormLayout(box)
            layout.setRowWrapPolicy(QtWidgets.QFormLayout.RowWrapPolicy.WrapLongRows)
            layout.setFieldGrowthPolicy(
                QtWidgets.QFormLayout.FieldGrowthPolicy.AllNonFixedFieldsGrow)
            for spec in specs:
                widget = F.make_field(obj, spec, self.task)
                if widget is None:
                    continue
                widget.setToolTip(spec.tooltip)
                label = QtWidgets.QLabel(_tr(spec.label))
                label.setToolTip(spec.tooltip)
                layout.addRow(label, widget)
                self.fields[spec.prop] = widget
                self.rows[spec.prop] = (label, widget)
            self.boxes.append((box, [s.prop for s in specs]))
            outer.addWidget(box)
        outer.addStretch(1)
        # names, not the object: they can be asked after the document is closed
        self.document_name, self.object_name = obj.Document.Name, obj.Name
        self.status = ""     # the last message, kept after the dialog (and its widgets) close
        self.worker = None
        self.inputs: dict = {}
        self.finished = False
        self.started = 0.0
        self.timer = QtCore.QTimer(self.form)
        self.timer.setInterval(POLL_MS)
        self.timer.timeout.connect(self.poll)
        self._connect_conditions()
        ACTIVE["panel"] = self

    # -- which fields show -------------------------------------------------------------
    def _connect_conditions(self) -> None:
        drivers = {spec.when[0] for spec in self.specs.values() if spec.when}
        for prop in drivers:
            widget = self.fields.get(prop)
            if isinstance(widget, QtWidgets.QComboBox):
                widget.currentIndexChanged.connect(lambda *_: self.update_visibility())
        tool = self.fields.get("Tool")
        if isinstance(tool, QtWidgets.QComboBox) and "Material" in self.fields:
            tool.currentIndexChanged.connect(lambda *_: self._tool_changed())
        self.update_visibility()

    def _tool_changed(self) -> None:
        material = self.fields["Material"]
        F.fill_combo(material, F.materials_of(self.fields["Tool"].currentText()),
                     F.combo_text(material), self.specs["Material"].empty_means or "none")

    def visible_fields(self) -> list[str]:
        return [p for p, (label, _) in self.rows.items() if not label.isHidden()]

    def update_visibility(self) -> None:
        texts = {prop: F.field_text(widget) for prop, widget in self.fields.items()}
        for prop, (label, widget) in self.rows.items():
            shown = self.specs[prop].shown(texts)
            label.setVisible(shown)
            widget.setVisible(shown)
        for box, props in self.boxes:
            box.setVisible(any(not self.rows[p][0].isHidden() for p in props if p in self.rows))

    # -- scripts and tests ---------------------------------------------------------------
    def set_field(self, name: str, value) -> None:
        """Type a value into a field as a user would (scripts and tests)."""
        F.set_field_value(self.specs[name], self.fields[name], value)

    def wait(self, timeout: float = 600.0) -> bool:
        """Keep the GUI going until a started computation is applied (scripts and tests)."""
        end = time.monotonic() + timeout
        while self.worker is not None and time.monotonic() < end:
            QtWidgets.QApplication.processEvents()
            time.sleep(0.02)
        return self.finished

    # -- OK: fields -> object -> worker -> one recompute ----------------------------------
    def copy_fields(self) -> bool:
        """Fields into the object, checked by the schema; False (message shown) on error."""
        from freecad_conformal.errors import ConformalError
        from freecad_conformal.objects.properties import values_from_object
        from freecad_conformal.settings.schema import validate

        try:
            for prop, widget in self.fields.items():
                if self.rows[prop][0].isHidden():
                    continue              # a field of another mode keeps its value
                setattr(self.obj, prop, F.field_value(self.specs[prop], widget))
            if self.settings:
                validate(self.settings, values_from_object(self.obj, self.settings))
        except (ValueError, ConformalError) as exc:
            self._say(False, str(exc))
            return False
        return True

    def apply(self) -> bool:
        """Start the computation (or, without a worker, recompute now); False when it failed
        to start or, done in place, failed."""
        if self.worker is not None or not self.copy_fields():
            return False
        from freecad_conformal.objects.computed import synchronous

        proxy = getattr(self.obj, "Proxy", None)
        if BACKGROUND["enabled"] and hasattr(proxy, "inputs") and self.task:
            return self._start(proxy)
        with synchronous():                      # the panel waits for this result itself
            self.obj.Document.recompute()
        return self._settle()

    def _start(self, proxy) -> bool:
        from freecad_conformal.errors import ConformalError
        from freecad_conformal.gui.worker import WorkerProcess

        try:
            self.inputs = proxy.inputs(self.obj)
        except ConformalError as exc:
            self._say(False, str(exc))
            return False
        self.worker = WorkerProcess(proxy.TASK, self.inputs).start()
        self.started = time.monotonic()
        self._busy(True)
        self.timer.start()
        return True

    def poll(self) -> None:
        """Timer tick: show the worker's progress; apply its outcome once it ends."""
        if self.worker is None:
            return
        if not self.object_alive():
            self._orphaned()
            return
        fraction, text = self.worker.progress()
        elapsed = time.monotonic() - self.started
        self.progress_line.setText(f"{text or _tr('starting')} ({elapsed:.0f} s)")
        if fraction is None:
            self.progress_bar.setRange(0, 0)
        else:
            self.progress_bar.setRange(0, 1000)
            self.progress_bar.setValue(int(1000 * fraction))
        _status_bar(f"Conformal: {self.form.windowTitle()}: {text}")
        outcome = self.worker.poll()
        if outcome is not None:
            self._finish(outcome)

    def object_alive(self) -> bool:
        """Whether the object (and its document) still exist: the user may close the
        document, or delete the object, while the worker runs."""
        document = FreeCAD.listDocuments().get(self.document_name)
        return document is not None and document.getObject(self.object_name) is not None

    def _orphaned(self) -> None:
        """The object went away under a running worker: stop it and close the panel."""
        self.timer.stop()
        self.worker.cancel()
        self.worker = None
        self.status = _tr("stopped: the document was closed")
        FreeCAD.Console.PrintMessage(
            f"Conformal: {self.form.windowTitle()} stopped: {self.document_name} was closed\n")
        FreeCADGui.Control.closeDialog()

    def _finish(self, outcome) -> None:
        from freecad_conformal.objects.computed import precompute

        self.timer.stop()
        self.worker = None
        self._busy(False)
        if outcome.traceback:
            FreeCAD.Console.PrintLog(f"Conformal worker:\n{outcome.traceback}\n")
        precompute(self.obj, self.inputs, outcome.as_precomputed())
        self.obj.touch()
        self.obj.Document.recompute()
        if self._settle():
            self.finished = True
            self.obj.Document.commitTransaction()
            FreeCADGui.Control.closeDialog()

    def _settle(self) -> bool:
        if not self.obj.isValid():
            status = self.obj.getStatusString() if hasattr(self.obj, "getStatusString") else ""
            self._say(False, status or _tr("failed: see the report view"))
            return False
        self._say(True, _tr("done"))
        return True

    def _busy(self, busy: bool) -> None:
        for widget in self.fields.values():
            widget.setEnabled(not busy)
        self.progress_bar.setVisible(busy)
        self.progress_line.setVisible(busy)
        if busy:
            self._say(True, _tr("working; the view stays live, Cancel stops it"))

    def _say(self, ok: bool, text: str) -> None:
        self.status = text
        (self.message.ok if ok else self.message.error)(text)

    # -- the dialog's buttons --------------------------------------------------------------
    def accept(self) -> bool:
        """OK: start the work; the dialog closes by itself once the result is applied."""
        if self.worker is not None:
            return False
        started = self.apply()
        if started and self.worker is None:        # computed in place
            self.finished = True
            self.obj.Document.commitTransaction()
            FreeCADGui.Control.closeDialog()
            return True
        return False

    def reject(self) -> bool:
        """Cancel: stop a running worker, remove the new object."""
        self.timer.stop()
        if self.worker is not None:
            self.worker.cancel()
            self.worker = None
        doc = self.obj.Document
        doc.abortTransaction()
        doc.recompute()
        FreeCADGui.Control.closeDialog()
        return True

    def getStandardButtons(self) -> int:  # noqa: N802 - FreeCAD's name
        return standard_buttons("Ok", "Cancel")


def _status_bar(text: str) -> None:
    window = FreeCADGui.getMainWindow()
    if window is not None:
        window.statusBar().showMessage(text, 2 * POLL_MS + 1000)
