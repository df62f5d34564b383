"""grblHAL: parenthesis comments, G93 inverse time, M62-M65 auxiliary outputs, T M6."""
from __future__ import annotations

from freecad_conformal.post.dialects.base import number
from freecad_conformal.post.dialects.linuxcnc import LinuxCNC
from freecad_conformal.post.machine import Machine


class GrblHal(LinuxCNC):
    name = "grblhal"

    def preamble(self, machine: Machine, relative_e: bool) -> list[str]:
        return ["G21 G90 G94 G17"]

    def dwell(self, seconds: float) -> str:
        return f"G4 P{number(seconds, 3)}"
