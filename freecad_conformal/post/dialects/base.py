"""What differs between controllers: comments, preamble, events, feed modes, extrusion."""
from __future__ import annotations

from freecad_conformal.post.machine import Machine
from freecad_conformal.tolerances import DEFAULT_LINEAR_TOLERANCE
from freecad_conformal.toolpath import Event


def number(value: float, decimals: int = 4) -> str:
    """Fixed-point without trailing zeros and without '-0' (G-code has no exponents)."""
    text = f"{value:.{decimals}f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def feed_number(value: float) -> str:
    """Feeds span 1e-4 (slow inverse time) to 1e5: keep about six significant digits."""
    decimals = 4
    magnitude = abs(value)
    while decimals < 10 and 0 < magnitude < 10.0 ** (2 - decimals):
        decimals += 1
    return number(value, decimals)


class Dialect:
    """Base dialect: override the class attributes and the hooks that differ."""

    name = "base"
    #: G93 inverse-time feed for moves with rotary motion
    inverse_time = False
    #: E words carry the extrusion on deposit moves
    extrusion = False

    def __init__(self, tolerance: float = DEFAULT_LINEAR_TOLERANCE) -> None:
        #: the post's linear tolerance (mm), for controllers that blend corners within one
        self.tolerance = tolerance

    def comment(self, text: str) -> str:
        return f"; {text}"

    def preamble(self, machine: Machine, relative_e: bool) -> list[str]:
        return ["G21", "G90"]

    def postamble(self, machine: Machine) -> list[str]:
        return ["M400"]

    def start(self, machine: Machine) -> list[str]:
        """Heat-up and homing before the first move, then the machine's own start code.

        Controllers without heater or homing commands in programs (LinuxCNC, grblHAL) get
        a comment saying what the operator must do first; their own M-codes, if any, go in
        the machine's start_gcode.
        """
        needs = [f"{heater} at {celsius:g} C" for heater, celsius in machine.temperatures]
        needs += ["homed"] if machine.home_on_start else []
        note = [self.comment(f"before starting: {', '.join(needs)} (dialect {self.name} does "
                             "not do this from the program)")] if needs else []
        return note + list(machine.start_gcode)

    def end(self, machine: Machine) -> list[str]:
        return list(machine.end_gcode)

    def power_on(self, machine: Machine, power: float) -> str:
        if machine.light_control == "analog":
            return f"M68 E0 Q{number(power * 100.0, 2)}"
        return f"M3 S{number(power * machine.spindle_max, 2)}"

    def power_off(self, machine: Machine) -> str:
        return "M68 E0 Q0" if machine.light_control == "analog" else "M5"

    def spindle(self, rpm: float) -> list[str]:
        """The milling spindle on at `rpm` (clockwise), or off for 0."""
        return [f"M3 S{int(round(rpm))}"] if rpm > 0 else ["M5"]

    def coolant(self, on: bool) -> list[str]:
        return ["M8" if on else "M9"]

    def dwell(self, seconds: float) -> str:
        return f"G4 P{number(seconds * 1000.0, 1)}"

    def tool_change(self, tool: int, machine: Machine) -> list[str]:
        return [f"T{tool}"]

    def extrusion_note(self, machine: Machine) -> str:
        """How the program drives the extruder, for the header."""
        return f"by E words (filament {machine.filament_diameter:g} mm)"

    def extruder(self, on: bool) -> list[str]:
        state = "on" if on else "off"
        return [self.comment(f"extruder {state}: E words on the moves drive it")]

    def event(self, event: Event, machine: Machine) -> list[str]:
        """Lines for one process event."""
        action = event.action
        if action in ("light_on", "laser_on"):
            return [self.power_on(machine, event.power)]
        if action in ("light_off", "laser_off"):
            return [self.power_off(machine)]
        if action in ("extruder_on", "extruder_off"):
            return self.extruder(action == "extruder_on")
        if action == "dwell":
            return [self.dwell(event.seconds)]
        if action in ("spindle_on", "spindle_off"):
            return self.spindle(event.rpm if action == "spindle_on" else 0.0)
        if action in ("coolant_on", "coolant_off"):
            return self.coolant(action == "coolant_on")
        return self.tool_change(event.tool, machine)
