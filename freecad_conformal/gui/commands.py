"""FreeCAD GUI commands (ids prefixed Conformal_); each calls the same code as the CLI.

A command only gathers the selection and opens a task panel or the dock; the work happens in
document objects (freecad_conformal.objects) or in the panels' sessions.
"""
from __future__ import annotations

import FreeCAD
import FreeCADGui

from freecad_conformal import RESOURCES
from freecad_conformal.gui.qt import translate


def icon(name: str) -> str:
    """Path of a command icon in resources/icons."""
    return str(RESOURCES / "icons" / f"{name}.svg")


def _tr(text: str) -> str:
    return translate("Conformal", text)


class ProcessPanelCommand:
    """Show the dock panel with the tool library and the DOE tabs."""

    def GetResources(self):  # noqa: N802 - FreeCAD's names
        return {"Pixmap": icon("Conformal_ProcessPanel"),
                "MenuText": _tr("Tools and DOE"),
                "ToolTip": _tr("Show the tool library and design-of-experiments panel")}

    def IsActive(self):  # noqa: N802
        return True

    def Activated(self):  # noqa: N802
        from freecad_conformal.gui.dock import process_panel

        process_panel()


class SectionsCommand:
    """Planar section stack of the selected solid, added to the document as wires."""

    def GetResources(self):  # noqa: N802
        return {"Pixmap": icon("Conformal_Sections"),
                "MenuText": _tr("Sections"),
                "ToolTip": _tr("Exact planar sections of the selected solid (1 mm spacing along Z)")}

    def IsActive(self):  # noqa: N802
        return bool(FreeCADGui.Selection.getSelection())

    def Activated(self):  # noqa: N802
        from freecad_conformal.errors import ConformalError
        from freecad_conformal.geometry import sections

        doc = FreeCAD.ActiveDocument
        for obj in FreeCADGui.Selection.getSelection():
            try:
                stack = sections.planar_sections(obj.Shape, layer=1.0)
            except ConformalError as exc:
                FreeCAD.Console.PrintError(f"Conformal sections of {obj.Label}: {exc}\n")
                continue
            doc.openTransaction("Conformal sections")
            result = doc.addObject("Part::Feature", f"{obj.Name}_Sections")
            result.Shape = stack.wires_compound()
            doc.commitTransaction()
        doc.recompute()


COMMANDS = {"Conformal_Sections": SectionsCommand,
            "Conformal_ProcessPanel": ProcessPanelCommand}


def register_all() -> list[str]:
    """Register every command with FreeCAD; returns their ids in toolbar order."""
    for name, cls in COMMANDS.items():
        FreeCADGui.addCommand(name, cls())
    return list(COMMANDS)
