"""LinuxCNC: parenthesis comments, G93 inverse time, G64 blending; no G43.4 (rejected)."""
from __future__ import annotations

from freecad_conformal.post.dialects.base import Dialect, number
from freecad_conformal.post.machine import Machine


class LinuxCNC(Dialect):
    name = "linuxcnc"
    inverse_time = True

    def comment(self, text: str) -> str:
        # a comment ends at the first ')' and cannot nest: drop parentheses from the text
        return "(" + text.replace("(", "[").replace(")", "]") + ")"

    def preamble(self, machine: Machine, relative_e: bool) -> list[str]:
        return ["G21 G90 G94 G17 G40 G49", f"G64 P{number(self.tolerance)}"]

    def postamble(self, machine: Machine) -> list[str]:
        return ["G94", "M5", "M2"]

    def dwell(self, seconds: float) -> str:
        return f"G4 P{number(seconds, 3)}"

    def tool_change(self, tool: int, machine: Machine) -> list[str]:
        # up to the machine's tool-change height first (machine coordinates), then the
        # tool table's length for the new tool (G43 H, along Z): the tip stays the
        # programmed point. A tilting head's tool is not along Z: there the post measures
        # the head pivots from each tool's tip itself (tool_lengths) and G43 stays off.
        retract = [] if machine.tool_change_z is None else [f"G53 G0 Z{number(machine.tool_change_z)}"]
        length = [f"G43 H{tool}"] if not machine.head_axes else []
        return retract + [f"T{tool} M6"] + length

    def extrusion_note(self, machine: Machine) -> str:
        return "by digital output 0 (switched with the deposit moves), no E words"

    def extruder(self, on: bool) -> list[str]:
        # digital output 0, synchronised with motion, switches the extruder drive
        return ["M64 P0" if on else "M65 P0"]
