"""Conformal: multi-axis additive manufacturing process planning on exact B-rep solids.

This package imports no FreeCAD module at import time, so its pure parts (toolpath, post,
process, stream) run in any Python with numpy.
"""
from __future__ import annotations

import re
from pathlib import Path

PACKAGE_ROOT = Path(__file__).resolve().parent
ADDON_ROOT = PACKAGE_ROOT.parent
RESOURCES = ADDON_ROOT / "resources"


def _read_version() -> str:
    """The version recorded in package.xml, the single source of truth for it."""
    try:
        text = (ADDON_ROOT / "package.xml").read_text(encoding="utf-8")
    except OSError:
        return "0+unknown"
    match = re.search(r"<version>([^<]+)</version>", text)
    return match.group(1).strip() if match else "0+unknown"


__version__ = _read_version()
