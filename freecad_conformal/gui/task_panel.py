"""A task panel that edits an object's parameter properties with units-aware fields.

Commands open it on the object they created inside an open document transaction: OK applies
the fields, recomputes and commits (one undo step); Cancel aborts the transaction, which
removes the new object. A failed recompute keeps the panel open with the error shown.
"""
from __future__ import annotations

from typing import Sequence

import FreeCAD
import FreeCADGui

from freecad_conformal.gui.qt import QtWidgets, standard_buttons, translate
from freecad_conformal.gui.widgets import MessageLine, quantity_field, quantity_value

#: FreeCAD property types shown as quantity fields, with the unit typed values default to.
QUANTITY_UNITS = {"App::PropertyLength": "mm", "App::PropertyDistance": "mm",
                  "App::PropertyAngle": "deg", "App::PropertySpeed": "mm/s",
                  "App::PropertyArea": "mm^2"}
#: The panel opened last (scripts and tests drive it).
ACTIVE: dict = {}


def _vector_text(vector) -> str:
    return f"{vector.x:g}, {vector.y:g}, {vector.z:g}"


def _parse_vector(text: str, name: str):
    try:
        x, y, z = (float(part) for part in text.replace(";", ",").split(","))
    except ValueError:
        raise ValueError(f"{name}: give three numbers 'x, y, z', got {text!r}") from None
    return FreeCAD.Vector(x, y, z)


class ObjectTaskPanel:
    """Fields for the editable properties of `obj` in `groups`."""

    def __init__(self, obj, groups: Sequence[str], title: str) -> None:
        self.obj = obj
        self.form = QtWidgets.QWidget()
        self.form.setWindowTitle(title)
        layout = QtWidgets.QFormLayout(self.form)
        self.fields: dict[str, tuple[str, QtWidgets.QWidget]] = {}
        for name in obj.PropertiesList:
            if obj.getGroupOfProperty(name) not in groups or obj.getEditorMode(name):
                continue
            kind = obj.getTypeIdOfProperty(name)
            widget = self._field(kind, name)
            if widget is not None:
                widget.setToolTip(obj.getDocumentationOfProperty(name))
                self.fields[name] = (kind, widget)
                layout.addRow(translate("Conformal", name), widget)
        self.message = MessageLine()
        layout.addRow(self.message)
        self.status = ""     # the last message, kept after the dialog (and its widgets) close
        ACTIVE["panel"] = self

    def _field(self, kind: str, name: str):
        value = getattr(self.obj, name)
        if kind in QUANTITY_UNITS:
            return quantity_field(QUANTITY_UNITS[kind], float(value.Value), -1e9, 1e9)
        if kind in ("App::PropertyInteger", "App::PropertyPercent"):
            widget = QtWidgets.QSpinBox()
            widget.setRange(0, 100 if kind == "App::PropertyPercent" else 1_000_000)
            widget.setValue(int(value))
            return widget
        if kind == "App::PropertyFloat":
            widget = QtWidgets.QDoubleSpinBox()
            widget.setRange(-1e9, 1e9)
            widget.setDecimals(4)
            widget.setValue(float(value))
            return widget
        if kind == "App::PropertyBool":
            widget = QtWidgets.QCheckBox()
            widget.setChecked(bool(value))
            return widget
        if kind == "App::PropertyEnumeration":
            widget = QtWidgets.QComboBox()
            widget.addItems(self.obj.getEnumerationsOfProperty(name))
            widget.setCurrentIndex(max(widget.findText(value), 0))
            return widget
        if kind == "App::PropertyString":
            return QtWidgets.QLineEdit(value)
        if kind == "App::PropertyVector":
            return QtWidgets.QLineEdit(_vector_text(value))
        return None    # links and outputs are set by the command, not typed

    def set_field(self, name: str, value) -> None:
        """Type a value into a field as a user would (scripts and tests)."""
        kind, widget = self.fields[name]
        if kind in QUANTITY_UNITS:
            widget.setProperty("rawValue", float(value))
        elif isinstance(widget, QtWidgets.QSpinBox):
            widget.setValue(int(value))
        elif isinstance(widget, QtWidgets.QDoubleSpinBox):
            widget.setValue(float(value))
        elif isinstance(widget, QtWidgets.QCheckBox):
            widget.setChecked(bool(value))
        elif isinstance(widget, QtWidgets.QComboBox):
            widget.setCurrentIndex(widget.findText(str(value)))
        else:
            widget.setText(str(value))

    def apply(self) -> bool:
        """Copy the fields into the object and recompute; False (message shown) on failure."""
        try:
            for name, (kind, widget) in self.fields.items():
                if kind in QUANTITY_UNITS:
                    setattr(self.obj, name, quantity_value(widget))
                elif isinstance(widget, (QtWidgets.QSpinBox, QtWidgets.QDoubleSpinBox)):
                    setattr(self.obj, name, widget.value())
                elif isinstance(widget, QtWidgets.QCheckBox):
                    setattr(self.obj, name, widget.isChecked())
                elif isinstance(widget, QtWidgets.QComboBox):
                    setattr(self.obj, name, widget.currentText())
                elif kind == "App::PropertyVector":
                    setattr(self.obj, name, _parse_vector(widget.text(), name))
                else:
                    setattr(self.obj, name, widget.text())
        except ValueError as exc:
            self._say(False, str(exc))
            return False
        self.obj.Document.recompute()
        if not self.obj.isValid():
            status = self.obj.getStatusString() if hasattr(self.obj, "getStatusString") else ""
            self._say(False, status or translate("Conformal", "failed: see the report view"))
            return False
        self._say(True, translate("Conformal", "done"))
        return True

    def _say(self, ok: bool, text: str) -> None:
        self.status = text
        (self.message.ok if ok else self.message.error)(text)

    def accept(self) -> bool:
        if not self.apply():
            return False
        self.obj.Document.commitTransaction()
        FreeCADGui.Control.closeDialog()
        return True

    def reject(self) -> bool:
        doc = self.obj.Document
        doc.abortTransaction()
        doc.recompute()
        FreeCADGui.Control.closeDialog()
        return True

    def getStandardButtons(self) -> int:  # noqa: N802 - FreeCAD's name
        return standard_buttons("Ok", "Cancel")
