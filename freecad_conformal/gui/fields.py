"""Widgets for the task panel's fields (gui/panel_layout.FieldSpec): quantity fields with
units, spin boxes with % or s, lists for tools, materials, dialects and the root direction,
three numbers for vectors. Each field is narrow enough for FreeCAD's combo view."""
from __future__ import annotations

import FreeCAD

from freecad_conformal.gui.panel_layout import FieldSpec
from freecad_conformal.gui.qt import QtCore, QtWidgets
from freecad_conformal.gui.widgets import (optional_quantity_field, quantity_field, quantity_value,
                                           set_quantity)

#: FreeCAD property types shown as quantity fields, with the unit typed values default to.
QUANTITY_UNITS = {"App::PropertyLength": "mm", "App::PropertyDistance": "mm",
                  "App::PropertyAngle": "deg", "App::PropertySpeed": "mm/s",
                  "App::PropertyArea": "mm^2", "App::PropertyVolume": "mm^3"}
#: Characters a list shows before it scrolls: keeps the panel inside the combo view.
LIST_WIDTH_CHARS = 12
#: Tool kinds the objects' tasks take (a plan deposits, a feature cures).
DEPOSITION = ("fdm_nozzle", "laser_nozzle")


def tool_ids(task: str) -> list[str]:
    """Tool ids of the library (preferences' folder) that suit `task`."""
    from freecad_conformal.gui import preferences
    from freecad_conformal.process.library import ToolLibrary

    try:
        library = ToolLibrary.load(user_dir=preferences.tool_library_dir())
    except Exception as exc:   # noqa: BLE001 - a broken library must not stop the panel
        FreeCAD.Console.PrintLog(f"Conformal: tool library not read: {exc}\n")
        return []
    if task == "job":
        return [t.id for t in library if t.kind in DEPOSITION]
    if task == "feature":
        return [t.id for t in library if t.kind not in DEPOSITION]
    return [t.id for t in library]


def materials_of(tool_id: str) -> list[str]:
    from freecad_conformal.gui import preferences
    from freecad_conformal.process.library import ToolLibrary

    try:
        return list(ToolLibrary.load(user_dir=preferences.tool_library_dir()).get(tool_id).settings)
    except Exception:   # noqa: BLE001 - an unknown tool has no materials to offer
        return []


def dialect_names() -> list[str]:
    from freecad_conformal.post.dialects import DIALECTS

    return list(DIALECTS)


def _combo(items: list[str], current: str, editable: bool, empty_means: str = ""):
    widget = QtWidgets.QComboBox()
    widget.setEditable(editable)
    widget.setSizeAdjustPolicy(
        QtWidgets.QComboBox.SizeAdjustPolicy.AdjustToMinimumContentsLengthWithIcon)
    widget.setMinimumContentsLength(LIST_WIDTH_CHARS)
    fill_combo(widget, items, current, empty_means)
    return widget


def empty_text(empty_means: str) -> str:
    """How a list shows its unset choice: "(the machine's)"."""
    return f"({empty_means.strip()})" if empty_means.strip() else ""


def combo_text(widget) -> str:
    """A list's value: "" for its unset choice."""
    text = widget.currentText().strip()
    if widget.count() and widget.currentIndex() == 0 and text == widget.itemText(0).strip() \
            and text.startswith("("):
        return ""
    return text


def fill_combo(widget, items: list[str], current: str, empty_means: str = "") -> None:
    """Items (an empty first item standing for `empty_means`), `current` selected."""
    widget.blockSignals(True)
    widget.clear()
    if empty_means:       # the unset choice reads as what it stands for
        widget.addItem(empty_text(empty_means))
        widget.setItemData(0, empty_means, QtCore.Qt.ItemDataRole.ToolTipRole)
    widget.addItems(items)
    index = widget.findText(current) if current else 0
    if index < 0 and current:
        widget.addItem(current)
        index = widget.count() - 1
    widget.setCurrentIndex(max(index, 0))
    if widget.isEditable() and empty_means:
        widget.lineEdit().setPlaceholderText(empty_means)
    widget.blockSignals(False)


class VectorField(QtWidgets.QWidget):
    """Three numbers x, y, z (with the unit after them when there is one)."""

    def __init__(self, vector, unit: str = "") -> None:
        super().__init__()
        layout = QtWidgets.QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        self.boxes = []
        for value in (vector.x, vector.y, vector.z):
            box = QtWidgets.QDoubleSpinBox()
            box.setRange(-1e6, 1e6)
            box.setDecimals(3)
            box.setValue(float(value))
            box.setMinimumWidth(40)
            self.boxes.append(box)
            layout.addWidget(box)
        if unit:
            layout.addWidget(QtWidgets.QLabel(unit))

    def vector(self):
        return FreeCAD.Vector(*(box.value() for box in self.boxes))

    def set_vector(self, values) -> None:
        for box, value in zip(self.boxes, values):
            box.setValue(float(value))


def make_field(obj, spec: FieldSpec, task: str):
    """The widget editing `spec.prop` of `obj`, holding its current value."""
    value = getattr(obj, spec.prop)
    kind = spec.type_id
    if spec.picks == "tools":
        return _combo(tool_ids(task), str(value), True, spec.empty_means)
    if spec.picks == "materials":
        tool = str(getattr(obj, "Tool", ""))
        return _combo(materials_of(tool), str(value), False, spec.empty_means or "none")
    if spec.picks == "dialects":
        return _combo(dialect_names(), str(value), False, spec.empty_means or "the machine's")
    if spec.picks == "root":
        return _combo(["auto", "as placed"], str(value), True)
    if kind in QUANTITY_UNITS:
        if spec.empty_means:
            return optional_quantity_field(QUANTITY_UNITS[kind], float(value.Value),
                                           spec.empty_means, -1e9, 1e9)
        return quantity_field(QUANTITY_UNITS[kind], float(value.Value), -1e9, 1e9)
    if kind in ("App::PropertyInteger", "App::PropertyPercent"):
        widget = QtWidgets.QSpinBox()
        widget.setRange(0, 100 if kind == "App::PropertyPercent" else 1_000_000)
        widget.setValue(int(value))
        if spec.unit:
            widget.setSuffix(f" {spec.unit}")
        return widget
    if kind == "App::PropertyFloat":
        widget = QtWidgets.QDoubleSpinBox()
        widget.setRange(-1e9, 1e9)
        widget.setDecimals(3)
        widget.setValue(float(value))
        if spec.unit:
            widget.setSuffix(f" {spec.unit}")
        return widget
    if kind == "App::PropertyBool":
        widget = QtWidgets.QCheckBox()
        widget.setChecked(bool(value))
        return widget
    if kind == "App::PropertyEnumeration":
        return _combo(list(obj.getEnumerationsOfProperty(spec.prop)), str(value), False)
    if kind == "App::PropertyVector":
        return VectorField(value, spec.unit)
    if kind == "App::PropertyString":
        widget = QtWidgets.QLineEdit(value)
        if spec.empty_means:
            widget.setPlaceholderText(spec.empty_means)
        return widget
    return None


def field_value(spec: FieldSpec, widget):
    """The value of a field as the property takes it."""
    if spec.type_id in QUANTITY_UNITS and not isinstance(widget, QtWidgets.QComboBox):
        return quantity_value(widget)
    if isinstance(widget, (QtWidgets.QSpinBox, QtWidgets.QDoubleSpinBox)):
        return widget.value()
    if isinstance(widget, QtWidgets.QCheckBox):
        return widget.isChecked()
    if isinstance(widget, QtWidgets.QComboBox):
        return combo_text(widget)
    if isinstance(widget, VectorField):
        return widget.vector()
    return widget.text()


def set_field_value(spec: FieldSpec, widget, value) -> None:
    """Type `value` into a field as a user would (scripts and tests)."""
    if spec.type_id in QUANTITY_UNITS and not isinstance(widget, QtWidgets.QComboBox):
        set_quantity(widget, float(value))
    elif isinstance(widget, QtWidgets.QSpinBox):
        widget.setValue(int(value))
    elif isinstance(widget, QtWidgets.QDoubleSpinBox):
        widget.setValue(float(value))
    elif isinstance(widget, QtWidgets.QCheckBox):
        widget.setChecked(bool(value))
    elif isinstance(widget, QtWidgets.QComboBox):
        index = widget.findText(str(value))
        if index < 0 and widget.isEditable():
            widget.setEditText(str(value))
        else:
            widget.setCurrentIndex(index)
    elif isinstance(widget, VectorField):
        widget.set_vector(value)
    else:
        widget.setText(str(value))


def field_text(widget) -> str:
    """What a field shows, for conditions (the Mode or Kind chosen)."""
    if isinstance(widget, QtWidgets.QComboBox):
        return widget.currentText()
    return ""
