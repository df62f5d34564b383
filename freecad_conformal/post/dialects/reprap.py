"""RepRapFirmware 3: ';' comments, E words, fan power as a fraction (M106 P0 S0..1)."""
from __future__ import annotations

from freecad_conformal.post.dialects.base import Dialect, number
from freecad_conformal.post.machine import Machine


class RepRapFirmware(Dialect):
    name = "reprap"
    extrusion = True

    def preamble(self, machine: Machine, relative_e: bool) -> list[str]:
        lines = ["G21", "G90", "M83" if relative_e else "M82"]
        return lines if relative_e else lines + ["G92 E0"]

    def postamble(self, machine: Machine) -> list[str]:
        return ["M400", self.power_off(machine)]

    def power_on(self, machine: Machine, power: float) -> str:
        if machine.light_control == "fan":
            return f"M106 P0 S{number(power, 3)}"
        return f"M3 S{number(power * machine.spindle_max, 2)}"

    def power_off(self, machine: Machine) -> str:
        return "M106 P0 S0" if machine.light_control == "fan" else "M5"
