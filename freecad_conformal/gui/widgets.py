"""Small form helpers shared by the panels: units-aware quantity fields, message labels."""
from __future__ import annotations

import FreeCADGui

from freecad_conformal.gui.qt import QtCore, QtWidgets

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


#: The Qt property naming what an optional quantity field's empty text stands for.
EMPTY_MEANS = "conformalEmptyMeans"


def optional_quantity_field(unit: str, value: float, empty_means: str, minimum: float = 0.0,
                            maximum: float = 1e9) -> QtWidgets.QWidget:
    """A quantity field for an optional setting, whose 0 stands for a derived value: shown
    empty, with `empty_means` greyed in it, rather than as "0.00 mm/s", which a user reads
    as zero. Emptied by the user, it holds 0 again (Gui::QuantitySpinBox alone keeps the
    last value it parsed and ignores Qt's special-value text)."""
    field = quantity_field(unit, value, minimum, maximum)
    field.setProperty(EMPTY_MEANS, empty_means)
    line = _line_edit(field)
    # The field is narrow: the first words say it (the tooltip says it all).
    line.setPlaceholderText(f"({empty_means.split(' (')[0]})")
    # The spin box writes "0.00 mm/s" back as it is shown and as it loses focus, after
    # those events reach any filter: empty it once Qt is done with them.
    field.installEventFilter(_UnsetShown(field))
    _show_unset(field)
    return field


class _UnsetShown(QtCore.QObject):
    """Empties an optional quantity field after it is shown or left holding 0, or left
    empty by the user (the spin box would put its last value back)."""

    EVENTS = (QtCore.QEvent.Type.Show, QtCore.QEvent.Type.FocusOut,
              QtCore.QEvent.Type.KeyPress)
    ENTER_KEYS = (QtCore.Qt.Key.Key_Return, QtCore.Qt.Key.Key_Enter)

    def __init__(self, field: QtWidgets.QWidget) -> None:
        super().__init__(field)
        self.field = field

    def eventFilter(self, watched, event) -> bool:  # noqa: N802 - Qt's name
        kind = event.type()
        if kind in self.EVENTS and (kind != QtCore.QEvent.Type.KeyPress
                                    or event.key() in self.ENTER_KEYS):
            emptied = not _line_edit(self.field).text().strip()
            QtCore.QTimer.singleShot(0, lambda: _show_unset(self.field, emptied))
        return False


def _line_edit(field: QtWidgets.QWidget) -> QtWidgets.QLineEdit:
    return field.findChild(QtWidgets.QLineEdit)


def _unset(field: QtWidgets.QWidget) -> bool:
    """Whether an optional quantity field stands for its derived value: empty or zero."""
    if not field.property(EMPTY_MEANS):
        return False
    line = _line_edit(field)
    return not line.text().strip() or float(field.property("rawValue")) == 0.0


def _show_unset(field: QtWidgets.QWidget, emptied: bool = False) -> None:
    """Show an optional quantity field holding 0 (or `emptied` by the user) empty."""
    try:
        if emptied or _unset(field):
            field.blockSignals(True)
            field.setProperty("rawValue", 0.0)
            _line_edit(field).clear()
            field.blockSignals(False)
    except RuntimeError:       # the panel closed before the timer fired
        pass


def quantity_value(field: QtWidgets.QWidget) -> float:
    """The value of a quantity field in FreeCAD's internal unit (mm, deg, ...); 0 for an
    optional field left empty (`optional_quantity_field`)."""
    if _unset(field):
        return 0.0
    return float(field.property("rawValue"))


def set_quantity(field: QtWidgets.QWidget, value: float) -> None:
    field.setProperty("rawValue", value)
    _show_unset(field)


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
