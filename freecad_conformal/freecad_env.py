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


_MODULES: tuple[ModuleType, ModuleType] | None = None


def import_freecad() -> tuple[ModuleType, ModuleType]:
    """Return (FreeCAD, Part), adding FreeCAD's library folder to sys.path when needed and,
    the first time, its Mod folders as FreeCAD's own start-up does (FreeCAD 1.0's Part looks
    up `PartEnums` in Mod/Part; without it Part.makeCompound crashes a plain Python)."""
    global _MODULES
    if _MODULES is not None:
        return _MODULES
    try:
        _MODULES = importlib.import_module("FreeCAD"), importlib.import_module("Part")
    except ImportError:
        for folder in FREECAD_LIB_DIRS:
            if folder not in sys.path:
                sys.path.append(folder)
            try:
                _MODULES = importlib.import_module("FreeCAD"), importlib.import_module("Part")
                break
            except ImportError:
                continue
    if _MODULES is not None:
        _add_mod_folders(_MODULES[0])
        return _MODULES
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
    import_freecad()          # which puts the Mod folders on sys.path


def _add_mod_folders(App) -> None:
    """FreeCAD's Mod folder and each module folder in it, appended to sys.path (after the
    user's own entries, as FreeCAD's start-up does)."""
    for root in (App.getResourceDir(), App.getHomePath()):
        folder = os.path.join(root, "Mod")
        if not os.path.isdir(folder):
            continue
        for path in [folder] + sorted(os.path.join(folder, name) for name in os.listdir(folder)):
            if os.path.isdir(path) and path not in sys.path:
                sys.path.append(path)


#: Environment variable naming the Python that worker processes run on (default: see
#: worker_python).
WORKER_PYTHON_VARIABLE = "CONFORMAL_WORKER_PYTHON"


def inside_freecad() -> bool:
    """Whether this interpreter is FreeCAD's own (FreeCAD, FreeCADCmd), whose executable
    cannot be started as a Python for worker processes."""
    return not os.path.basename(sys.executable or "").lower().startswith("python")


def worker_python() -> str:
    """The Python for workers: $CONFORMAL_WORKER_PYTHON, this interpreter when it is a
    Python (a venv, a plain python3), else the system's python of FreeCAD's version."""
    import shutil

    chosen = os.environ.get(WORKER_PYTHON_VARIABLE)
    if chosen:
        return chosen
    if not inside_freecad():
        return sys.executable
    # FreeCAD's own Python first (its prefix): one found on PATH (pyenv, conda) may be the
    # same version with another standard library, whose compiled modules do not load here
    version = f"python{sys.version_info.major}.{sys.version_info.minor}"
    for name in (version, "python3"):
        candidate = os.path.join(sys.base_exec_prefix, "bin", name)
        if os.access(candidate, os.X_OK):
            return candidate
    return shutil.which(version) or shutil.which("python3") or "/usr/bin/python3"
