"""Workbench set-up: toolbars and menus built from the registered commands."""
from __future__ import annotations

import FreeCAD

#: Command ids shown in the toolbar and menu, in order. Commands register themselves in
#: freecad_conformal.gui.commands.
TOOLBAR_COMMANDS: list[str] = []


def initialize(workbench) -> None:
    from freecad_conformal.gui import commands

    names = commands.register_all()
    TOOLBAR_COMMANDS[:] = names
    if names:
        workbench.appendToolbar("Conformal", names)
        workbench.appendMenu("&Conformal", names)
    FreeCAD.Console.PrintLog("Conformal workbench initialised\n")


def activated() -> None:
    FreeCAD.Console.PrintMessage("Conformal workbench active\n")
