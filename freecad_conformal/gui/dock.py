"""The dockable "Conformal process" panel: Tool library and DOE tabs sharing one library."""
from __future__ import annotations

import FreeCADGui

from freecad_conformal.gui import preferences
from freecad_conformal.gui.doe_tab import DoeTab
from freecad_conformal.gui.qt import QtCore, QtWidgets, translate
from freecad_conformal.gui.tool_session import ToolSession
from freecad_conformal.gui.tool_tab import ToolLibraryTab

DOCK_NAME = "ConformalProcessPanel"


class ProcessPanel(QtWidgets.QDockWidget):
    """Dock widget with the tool library and DOE tabs."""

    def __init__(self, parent=None) -> None:
        super().__init__(translate("Conformal", "Conformal process"), parent)
        self.setObjectName(DOCK_NAME)
        self.session = ToolSession.load(user_dir=preferences.tool_library_dir())
        self.tabs = QtWidgets.QTabWidget()
        self.tools = ToolLibraryTab(self.session)
        self.doe = DoeTab(lambda: self.session.library)
        self.tabs.addTab(self.tools, translate("Conformal", "Tool library"))
        self.tabs.addTab(self.doe, translate("Conformal", "DOE"))
        # a DOE setting written into a tool shows in the tool tab; new tools in the DOE combo
        self.tabs.currentChanged.connect(self._tab_changed)
        self.setWidget(self.tabs)

    def _tab_changed(self, index: int) -> None:
        if self.tabs.widget(index) is self.tools:
            self.tools.refresh()
        else:
            self.doe.refresh_tools()


def process_panel(show: bool = True) -> ProcessPanel:
    """The panel docked on the right of FreeCAD's main window (created once)."""
    window = FreeCADGui.getMainWindow()
    panel = window.findChild(QtWidgets.QDockWidget, DOCK_NAME)
    if panel is None:
        panel = ProcessPanel(window)
        window.addDockWidget(QtCore.Qt.DockWidgetArea.RightDockWidgetArea, panel)
    if show:
        panel.show()
        panel.raise_()
    return panel
