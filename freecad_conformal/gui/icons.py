"""Icon paths (resources/icons), shared by commands and view providers."""
from __future__ import annotations

from freecad_conformal import RESOURCES


def icon(name: str) -> str:
    """Path of an icon in resources/icons."""
    return str(RESOURCES / "icons" / f"{name}.svg")
