"""A hybrid sequence -> one neutral toolpath: deposit, cut and travel in one program.

Moves: inside a layer the head travels straight in the layer's top plane; between layers it
rises along the new axis first; a milling pass is reached from its clearance plane (the
safe sphere's extent along the tool axis) and left back to it; any move that turns the
tool axis or switches process goes over the safe sphere round everything the plan builds
(`paths.approach.transition`). Events: the deposition tool's laser (when it has one) and
feed on around each deposit; tool change, spindle and coolant around each milling session,
and between two cutters inside one.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from freecad_conformal.paths.approach import SAFE_MARGIN, exit_distance, transition
from freecad_conformal.paths.assemble import Feeds, in_layer_travel
from freecad_conformal.paths.bead import bead_area
from freecad_conformal.paths.hybrid import HybridSequence
from freecad_conformal.paths.map3d import Path3D
from freecad_conformal.paths.milling import MillPass
from freecad_conformal.toolpath import Toolpath, ToolpathBuilder


@dataclass
class DepositProcess:
    """How the deposition tool is driven: its T number, bead, feeds, laser power (0..1,
    None without a laser)."""

    tool: int
    width: float
    bead_model: str
    feeds: Feeds
    laser_power: float | None = None


@dataclass
class HybridPath:
    toolpath: Toolpath
    deposits: list[Path3D]
    travels: list[np.ndarray]
    cuts: list[np.ndarray] = field(default_factory=list)


#: A pass is approached at travel speed to this far (mm) above its start along the tool
#: axis, then entered at the plunge feed: the start stands on or beside the part, and the
#: gap is clear of it (the clearance plane is tens of millimetres up).
APPROACH_GAP = 2.0


class _Writer:
    def __init__(self, centre: np.ndarray, radius: float, process: DepositProcess,
                 metadata: dict) -> None:
        self.builder = ToolpathBuilder(**metadata)
        self.centre, self.radius = centre, radius
        self.process = process
        self.position: np.ndarray | None = None
        self.axis: np.ndarray | None = None
        self.travels: list[np.ndarray] = []
        self.cuts: list[np.ndarray] = []
        self.tool: int | None = None

    def travel(self, points: np.ndarray, axes: np.ndarray) -> None:
        self.builder.add_segment(points, axes, kind="travel", feed=self.process.feeds.travel,
                                 tool=self.tool or 0)
        start = self.position[None] if self.position is not None else points[:1]
        self.travels.append(np.vstack((start, points)))
        self.position, self.axis = points[-1], axes[-1]

    def safely_to(self, start: np.ndarray, axis: np.ndarray) -> None:
        """Over the safe sphere to `start` (the first move comes down from above it)."""
        if self.position is None:
            lift = exit_distance(start, axis, self.centre, self.radius + SAFE_MARGIN) + 1.0
            self.travel(np.array([start + lift * axis, start]), np.array([axis, axis]))
            return
        points, axes = transition(self.position, self.axis, start, axis, self.centre, self.radius)
        self.travel(points, axes)

    def change_tool(self, tool: int) -> None:
        if self.tool != tool:
            self.builder.event("tool_change", tool=tool)
            self.tool = tool

    def clearance(self, axis: np.ndarray) -> float:
        """Height along `axis` above which nothing of the plan stands."""
        return float(self.centre @ axis) + self.radius + SAFE_MARGIN

    def deposit_layer(self, paths: list[Path3D], new_session: bool) -> None:
        process = self.process
        for k, path in enumerate(paths):
            start, axis = path.points[0], path.axis
            if new_session or self.axis is None or not np.allclose(axis, self.axis):
                self.safely_to(start, axis)
            else:
                points = in_layer_travel(self.position, start, axis, k == 0)
                if len(points):
                    self.travel(points, np.tile(axis, (len(points), 1)))
            new_session = False
            if process.laser_power is not None:
                self.builder.event("laser_on", power=process.laser_power)
            self.builder.event("extruder_on")
            self.builder.add_segment(path.points[1:] if len(path.points) > 1 else path.points,
                                     axis, kind="deposit", feed=process.feeds.for_path(path),
                                     tool=process.tool,
                                     flow=bead_area(path.width or process.width, path.thickness,
                                                    process.bead_model))
            self.builder.event("extruder_off")
            if process.laser_power is not None:
                self.builder.event("laser_off")
            self.position, self.axis = path.points[-1], axis

    def mill(self, passes: list[MillPass]) -> None:
        spindle = None
        for cut in passes:
            tool = cut.tool
            if tool.number != self.tool:
                if spindle is not None:
                    self.builder.event("spindle_off")
                self.change_tool(tool.number)
                self.builder.event("spindle_on", rpm=tool.rpm)
                if spindle is None:
                    self.builder.event("coolant_on")
                spindle = tool.number
            start, axis = cut.points[0], cut.axis
            above = start + (self.clearance(axis) - float(start @ axis)) * axis
            near = start + APPROACH_GAP * axis
            if self.axis is not None and np.allclose(axis, self.axis) and self.position is not None:
                up = self.position + (self.clearance(axis) - float(self.position @ axis)) * axis
                self.travel(np.array([up, above, near]), np.array([axis, axis, axis]))
            else:
                self.safely_to(above, axis)
                self.travel(near[None], axis[None])
            self.builder.add_segment(start[None], axis, kind="cut", feed=tool.plunge_feed,
                                     tool=tool.number)
            lead = cut.lead if len(cut.points) > 2 * cut.lead + 1 else 0
            if lead:
                self.travel(cut.points[1:1 + lead], np.repeat(axis[None], lead, axis=0))
            cutting = cut.points[1 + lead:len(cut.points) - lead]
            if len(cutting):
                self.builder.add_segment(cutting, axis, kind="cut", feed=cut.feed,
                                         tool=tool.number)
            if lead:
                self.travel(cut.points[len(cut.points) - lead:],
                            np.repeat(axis[None], lead, axis=0))
            self.cuts.append(cut.points)
            self.position, self.axis = cut.points[-1], axis
            up = self.position + (self.clearance(axis) - float(self.position @ axis)) * axis
            self.travel(up[None], axis[None])
        if spindle is not None:
            self.builder.event("coolant_off")
            self.builder.event("spindle_off")


def hybrid_toolpath(sequence: HybridSequence, deposit: DepositProcess, centre: np.ndarray,
                    radius: float, **metadata: str) -> HybridPath:
    """The program of a hybrid sequence; `centre`, `radius`: a sphere holding the part."""
    process = deposit
    writer = _Writer(np.asarray(centre, dtype=float), float(radius), process, metadata)
    deposits: list[Path3D] = []
    milled = True
    for step in sequence.steps:
        if step.kind == "deposit":
            if not step.paths:
                continue
            writer.change_tool(process.tool)
            writer.deposit_layer(step.paths, new_session=milled)
            deposits += step.paths
            milled = False
        elif step.session is not None and step.session.passes:
            writer.mill(step.session.passes)
            milled = True
    if writer.position is not None:
        up = writer.position + (exit_distance(writer.position, writer.axis, writer.centre,
                                              writer.radius + SAFE_MARGIN) + 1.0) * writer.axis
        writer.travel(up[None], writer.axis[None])
    return HybridPath(writer.builder.build(), deposits, writer.travels, writer.cuts)
