"""G-code dialects by name: each module defines one `Dialect` subclass."""
from __future__ import annotations

from freecad_conformal.errors import PostError
from freecad_conformal.post.dialects.base import Dialect
from freecad_conformal.post.dialects.grblhal import GrblHal
from freecad_conformal.post.dialects.linuxcnc import LinuxCNC
from freecad_conformal.post.dialects.marlin import Marlin
from freecad_conformal.post.dialects.reprap import RepRapFirmware
from freecad_conformal.tolerances import DEFAULT_LINEAR_TOLERANCE

DIALECTS: dict[str, type[Dialect]] = {
    cls.name: cls for cls in (LinuxCNC, Marlin, RepRapFirmware, GrblHal)
}


def get_dialect(name: str, tolerance: float = DEFAULT_LINEAR_TOLERANCE) -> Dialect:
    """A dialect instance by name; PostError naming the known ones otherwise."""
    try:
        return DIALECTS[name.lower()](tolerance)
    except KeyError:
        raise PostError(f"unknown G-code dialect {name!r}; known: {', '.join(DIALECTS)}") from None
