"""Marlin 2.1 multi-axis: ';' comments, rotary axes in degrees, E absolute or relative.

No inverse time: F is computed so the tool tip moves at the requested speed given that
Marlin applies F to the linear distance (or to degrees when only rotary axes move).
A light or laser runs from the spindle/laser output (M3/M5) or a fan output (M106/M107).
"""
from __future__ import annotations

from freecad_conformal.post.dialects.base import Dialect, number
from freecad_conformal.post.machine import Machine


_SET = {"hotend": "M104", "bed": "M140"}
_WAIT = {"hotend": "M109", "bed": "M190"}


class Marlin(Dialect):
    name = "marlin"
    extrusion = True

    def preamble(self, machine: Machine, relative_e: bool) -> list[str]:
        lines = ["G21", "G90", "M83" if relative_e else "M82"]
        return lines if relative_e else lines + ["G92 E0"]

    def postamble(self, machine: Machine) -> list[str]:
        heaters_off = [f"{_SET[heater]} S0" for heater, _ in machine.temperatures]
        return ["M400", self.power_off(machine)] + heaters_off

    def start(self, machine: Machine) -> list[str]:
        """Heat bed and hot end together, home while they heat, then wait for both: the
        firmware refuses cold extrusion, so a program without this stops at the first E."""
        heat = dict(machine.temperatures)
        lines = [f"{_SET[h]} S{number(heat[h], 1)}" for h in ("bed", "hotend") if h in heat]
        lines += ["G28"] if machine.home_on_start else []
        lines += [f"{_WAIT[h]} S{number(heat[h], 1)}" for h in ("bed", "hotend") if h in heat]
        return lines + list(machine.start_gcode)

    def power_on(self, machine: Machine, power: float) -> str:
        if machine.light_control == "fan":
            return f"M106 S{round(power * 255)}"
        return f"M3 S{number(power * machine.spindle_max, 2)}"

    def power_off(self, machine: Machine) -> str:
        return "M107" if machine.light_control == "fan" else "M5"
