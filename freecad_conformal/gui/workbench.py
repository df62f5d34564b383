"""Workbench set-up: toolbars and menus built from the registered commands, the preference
page and the translations folder."""
from __future__ import annotations

import FreeCAD
import FreeCADGui

from freecad_conformal import RESOURCES

#: Command ids shown in the toolbar and menu, in order. Commands register themselves in
#: freecad_conformal.gui.commands.
TOOLBAR_COMMANDS: list[str] = []


def initialize(workbench) -> None:
    from freecad_conformal.gui import commands
    from freecad_conformal.gui.preferences import PreferencesPage

    names = commands.register_all()
    TOOLBAR_COMMANDS[:] = names
    if names:
        workbench.appendToolbar("Conformal", names)
        workbench.appendMenu("&Conformal", names)
    # the preferences dialog looks up its group's icon by name ("preferences-conformal")
    FreeCADGui.addIconPath(str(RESOURCES / "icons"))
    FreeCADGui.addPreferencePage(PreferencesPage, "Conformal")
    translations = RESOURCES / "translations"
    if translations.is_dir():
        FreeCADGui.addLanguagePath(str(translations))
        FreeCADGui.updateLocale()
    FreeCAD.Console.PrintLog("Conformal workbench initialised\n")


#: Shown in the status bar on activation (milliseconds): the report view stays for results.
STATUS_MESSAGE_MS = 3000
_WARNED: list[bool] = []


def activated() -> None:
    from freecad_conformal.dependencies import install_hint, missing

    window = FreeCADGui.getMainWindow()
    if window is not None:
        window.statusBar().showMessage("Conformal workbench active", STATUS_MESSAGE_MS)
    hint = install_hint(missing())
    if hint and not _WARNED:
        _WARNED.append(True)
        FreeCAD.Console.PrintWarning(hint)
