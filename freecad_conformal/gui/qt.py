"""Qt through FreeCAD's PySide shim. FreeCAD 0.20 (Debian) has no PySide.QtWidgets: its
QtGui carries the widgets; FreeCAD 1.x has both. Import Qt names from here."""
from PySide import QtCore, QtGui

try:
    from PySide import QtWidgets
except ImportError:  # FreeCAD 0.20's shim: widgets live in QtGui
    QtWidgets = QtGui

__all__ = ["QtCore", "QtGui", "QtWidgets", "standard_buttons", "translate"]


def standard_buttons(*names: str) -> int:
    """A task panel's buttons as the int FreeCAD asks for, e.g. standard_buttons("Ok",
    "Cancel"). Full enum names and no int() of an enum: PySide6's enums are Python enums,
    whose flags int() refuses and whose short names exist only in its forgiveness mode."""
    total = 0
    for name in names:
        button = getattr(QtWidgets.QDialogButtonBox.StandardButton, name)
        total |= int(getattr(button, "value", button))
    return total


def translate(context: str, text: str) -> str:
    """Translatable text (FreeCAD's translation tables; the text itself when none loaded)."""
    return QtWidgets.QApplication.translate(context, text)
