"""Finding FreeCAD's Python modules from a plain Python (venv, CI) or inside FreeCAD."""
from __future__ import annotations

import importlib
import os
import sys
from types import ModuleType

from freecad_conformal.errors import ConformalError

#: Where distributions install FreeCAD's Python library (Debian/Ubuntu first).
FREECAD_LIB_DIRS = (
    "/usr/lib/freecad-python3/lib",
    "/usr/lib/freecad/lib",
    "/usr/local/lib/freecad/lib",
    "/usr/local/lib",
)


def import_freecad() -> tuple[ModuleType, ModuleType]:
    """Return (FreeCAD, Part), adding FreeCAD's library folder to sys.path when needed."""
    try:
        return importlib.import_module("FreeCAD"), importlib.import_module("Part")
    except ImportError:
        pass
    for folder in FREECAD_LIB_DIRS:
        if folder not in sys.path:
            sys.path.append(folder)
        try:
            return importlib.import_module("FreeCAD"), importlib.import_module("Part")
        except ImportError:
            continue
    raise ConformalError(
        "FreeCAD's Python modules were not found (looked in "
        + ", ".join(FREECAD_LIB_DIRS)
        + "). Install FreeCAD (Debian: apt-get install freecad) and run with /usr/bin/python3 "
        "or the project's venv."
    )


def make_workbench_types_loadable() -> None:
    """Put FreeCAD's Mod folders on sys.path, as FreeCAD's own start-up does.

    Opening a document loads the module of each object type (PartDesign::Body needs the
    `PartDesign` package from Mod/). From a plain Python those folders are not on sys.path,
    and FreeCAD then drops the objects silently: a document of PartDesign bodies would look
    empty. Documents made from Python need it too (doc.addObject("PartDesign::Body")).
    """
    App, _Part = import_freecad()
    for root in (App.getResourceDir(), App.getHomePath()):
        folder = os.path.join(root, "Mod")
        if os.path.isdir(folder) and folder not in sys.path:
            sys.path.append(folder)
