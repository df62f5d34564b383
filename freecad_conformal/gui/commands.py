"""FreeCAD GUI commands (ids prefixed Conformal_); each calls the same code as the CLI."""
from __future__ import annotations

import FreeCAD
import FreeCADGui

from freecad_conformal import RESOURCES


def icon(name: str) -> str:
    return str(RESOURCES / "icons" / f"{name}.svg")


class SectionsCommand:
    """Planar section stack of the selected solid, added to the document as wires."""

    def GetResources(self):
        return {
            "Pixmap": icon("Conformal"),
            "MenuText": "Sections",
            "ToolTip": "Exact planar sections of the selected solid (1 mm spacing along Z)",
        }

    def IsActive(self):
        return bool(FreeCADGui.Selection.getSelection())

    def Activated(self):
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


COMMANDS = {"Conformal_Sections": SectionsCommand}


def register_all() -> list[str]:
    for name, cls in COMMANDS.items():
        FreeCADGui.addCommand(name, cls())
    return list(COMMANDS)
