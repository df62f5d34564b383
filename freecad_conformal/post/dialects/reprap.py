"""RepRapFirmware 3: Marlin's program structure; fan power as a fraction (M106 P0 S0..1)."""
from __future__ import annotations

from freecad_conformal.post.dialects.base import number
from freecad_conformal.post.dialects.marlin import Marlin
from freecad_conformal.post.machine import Machine


class RepRapFirmware(Marlin):
    name = "reprap"

    def power_on(self, machine: Machine, power: float) -> str:
        if machine.light_control == "fan":
            return f"M106 P0 S{number(power, 3)}"
        return f"M3 S{number(power * machine.spindle_max, 2)}"

    def power_off(self, machine: Machine) -> str:
        return "M106 P0 S0" if machine.light_control == "fan" else "M5"
