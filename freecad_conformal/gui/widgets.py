"""Small form helpers shared by the panels: units-aware quantity fields, message labels."""
from __future__ import annotations

import FreeCADGui

from freecad_conformal.gui.qt import QtWidgets

#: Colours of the message line: errors red, confirmations green (readable on light themes).
ERROR_STYLE = "color: #b00020;"
OK_STYLE = "color: #1b6e20;"


def quantity_field(unit: str, value: float, minimum: float = 0.0,
                   maximum: float = 1e9) -> QtWidgets.QWidget:
    """A Gui::QuantitySpinBox (accepts '2 mm', '0.1 in', '30 deg') holding `value` in
    FreeCAD's internal unit of `unit` (mm, deg, mm/s)."""
    field = FreeCADGui.UiLoader().createWidget("Gui::QuantitySpinBox")
    field.setProperty("unit", unit)
    field.setProperty("minimum", minimum)
    field.setProperty("maximum", maximum)
    field.setProperty("rawValue", value)
    return field


def quantity_value(field: QtWidgets.QWidget) -> float:
    """The value of a quantity field in FreeCAD's internal unit (mm, deg, ...)."""
    return float(field.property("rawValue"))


def set_quantity(field: QtWidgets.QWidget, value: float) -> None:
    field.setProperty("rawValue", value)


class MessageLine(QtWidgets.QLabel):
    """One line of feedback under a form: validation errors or what was done."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.setWordWrap(True)

    def error(self, text: str) -> None:
        self.setStyleSheet(ERROR_STYLE)
        self.setText(text)

    def ok(self, text: str) -> None:
        self.setStyleSheet(OK_STYLE)
        self.setText(text)
