"""Conformal: multi-axis additive manufacturing process planning on exact B-rep solids.

This package imports no FreeCAD module at import time, so its pure parts (toolpath, post,
process, stream) run in any Python with numpy. It imports shapely where there is one, to take
shapely 2.1.0's per-call signature checks off the hot path (`shapely_speed.py`).
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

try:
    from freecad_conformal.shapely_speed import unwrap_slow_checks

    unwrap_slow_checks()
except ImportError:  # no shapely: the pure parts (toolpath, post, stream) do not need it
    pass
