"""A feature program under construction: tools and tool changes, the widths each cure makes,
the process notes for the header, and the final clearance check of every move.

`FeatureProgram.finish` builds the toolpath, writes what the program cures into its
metadata (`process`: widths, feeds, power and energy per tool; `tools`: the tool numbers;
`tool_choice`: why each tool was chosen) and checks every move against the tool envelopes
(paths/features/clearance.py) under the collision rule asked:

- `envelope` (default): every pose of every move, cures included, against the part and
  what is built before it;
- `published`: the layout is accepted by the published rule (i) (rods), so cure moves are
  not tested; travels, approaches and tool changes are still tested against the envelope.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from freecad_conformal.errors import PlanError
from freecad_conformal.paths.features import clearance
from freecad_conformal.paths.features.feeds import CureSetting
from freecad_conformal.paths.features.moves import HOME_LIFT
from freecad_conformal.process.tools import Tool
from freecad_conformal.toolpath import KINDS, Toolpath, ToolpathBuilder

COLLISION_RULES = ("envelope", "published")


@dataclass
class FeatureProgram:
    what: str
    builder: ToolpathBuilder = field(init=False)
    tools: dict[int, Tool] = field(default_factory=dict)
    current: int | None = None
    notes: list[str] = field(default_factory=list)
    choices: list[str] = field(default_factory=list)
    #: (point, axis) where the last feature left the tool (the retract above its last cure);
    #: the planners set it when they end
    last: tuple[np.ndarray, np.ndarray] | None = None
    _widths: dict[tuple[int, float], tuple[float, float]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.builder = ToolpathBuilder(part=self.what, material="UV resin")

    def number(self, tool: Tool) -> int:
        """The tool's number in this program (T1, T2... in the order first used)."""
        for number, known in self.tools.items():
            if known.id == tool.id:
                return number
        number = len(self.tools) + 1
        self.tools[number] = tool
        return number

    def enter(self, tool: Tool, point: np.ndarray, axis: np.ndarray) -> int:
        """Make `tool` current for a feature starting at `point` along `axis`. After an
        earlier feature the tool first retracts `HOME_LIFT` mm along its last axis (home),
        changes if another tool is needed, and comes back `HOME_LIFT` mm out along the new
        axis, so the feature's own approach starts from there. Returns the tool number."""
        number = self.number(tool)
        if self.last is not None:
            last_point, last_axis = self.last
            self.builder.add_segment([last_point + HOME_LIFT * last_axis], axes=last_axis,
                                     kind="travel", feed=600.0, tool=self.current or number)
        if number != self.current:
            self.builder.event("tool_change", tool=number)
            self.current = number
        if self.last is not None:
            self.builder.add_segment([np.asarray(point) + HOME_LIFT * np.asarray(axis)], axes=axis,
                                     kind="travel", feed=600.0, tool=number)
        return number

    def cures(self, tool_number: int, setting: CureSetting, what: str,
              thickness: float | None = None) -> None:
        """Record that cures of `tool_number` at `setting.feed` make lines `setting.width`
        wide and `thickness` thick along the tool axis (default: round, as rods are)."""
        self._widths[(tool_number, round(setting.feed, 9))] = (setting.width,
                                                               thickness or setting.width)
        tool = self.tools[tool_number]
        self.notes.append(f"T{tool_number} {tool.id}: " + setting.describe(what))

    def power_fraction(self, tool_number: int, setting: CureSetting) -> float:
        levels = getattr(self.tools[tool_number].spec, "power_levels", None) or [setting.power]
        return min(setting.power / max(levels), 1.0)

    def cured_sizes(self, tp: Toolpath) -> tuple[np.ndarray, np.ndarray]:
        """Per segment the width and thickness it cures (0 for other moves)."""
        cure = KINDS.index("cure")
        widths, thicknesses = np.zeros(tp.segment_count), np.zeros(tp.segment_count)
        for s in np.flatnonzero(tp.kind == cure):
            key = (int(tp.tool[s]), round(float(tp.feed[s]), 9))
            if key not in self._widths:
                raise PlanError(f"{self.what}: cure segment {s} at {tp.feed[s]:g} mm/min has no "
                                "recorded width (a planner bug)")
            widths[s], thicknesses[s] = self._widths[key]
        return widths, thicknesses

    def finish(self, part_points: np.ndarray | None, rule: str = "envelope") -> Toolpath:
        """Build, annotate and check the program (PlanError on any contact)."""
        if rule not in COLLISION_RULES:
            raise PlanError(f"{self.what}: collision rule must be one of "
                            f"{', '.join(COLLISION_RULES)}, got {rule!r}")
        self.builder.metadata["process"] = "; ".join(dict.fromkeys(self.notes))
        self.builder.metadata["tools"] = ", ".join(f"T{n} {t.id}" for n, t in self.tools.items())
        if self.choices:
            self.builder.metadata["tool_choice"] = "; ".join(self.choices)
        self.builder.metadata["collision_rule"] = rule
        tp = self.builder.build()
        widths, thicknesses = self.cured_sizes(tp)
        envelopes = {n: t.envelope for n, t in self.tools.items()}
        contacts = clearance.check_toolpath(tp, envelopes, widths, part_points,
                                            cured_thickness=thicknesses)
        if rule == "published":
            contacts = [c for c in contacts if c.kind != "cure"]
        if contacts:
            first, worst = contacts[0], max(contacts, key=lambda c: c.overlap)
            raise PlanError(f"{self.what}: {len(contacts)} move(s) of the tool envelope hit the "
                            f"part or what is built: first the {first.kind} move of segment "
                            f"{first.segment} hits {first.obstacle} by {first.overlap:.3f} mm "
                            f"at ({', '.join(f'{v:.2f}' for v in first.point)}); worst "
                            f"{worst.overlap:.3f} mm")
        return tp


def energy_line(tp: Toolpath) -> str:
    """'E J cured over L mm' for reports."""
    summary = tp.summary()
    return (f"{summary.energy:.3f} J cured over {summary.length_by_kind['cure']:.1f} mm "
            f"in {summary.time_s / 60:.1f} min")

