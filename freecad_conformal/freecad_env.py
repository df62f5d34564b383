"""Finding FreeCAD's Python modules from a plain Python (venv, CI) or inside FreeCAD."""
from __future__ import annotations

import importlib
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
