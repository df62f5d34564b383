"""Qt through FreeCAD's PySide shim. FreeCAD 0.20 (Debian) has no PySide.QtWidgets: its
QtGui carries the widgets; FreeCAD 1.x has both. Import Qt names from here."""
from PySide import QtCore, QtGui

try:
    from PySide import QtWidgets
except ImportError:  # FreeCAD 0.20's shim: widgets live in QtGui
    QtWidgets = QtGui

__all__ = ["QtCore", "QtGui", "QtWidgets", "translate"]


def translate(context: str, text: str) -> str:
    """Translatable text (FreeCAD's translation tables; the text itself when none loaded)."""
    return QtWidgets.QApplication.translate(context, text)
