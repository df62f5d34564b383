"""Independent check of an emitted program: read it back, replay it through forward
kinematics and measure how far the tool strays from the designed toolpath.

The reader (`gcode_reader`) knows only G-code and shares no state with the post. Each
block is sampled in joint space (the controller interpolates joints linearly), mapped to
tool-tip poses in the part frame, and compared with the designed polyline both ways: every
replayed sample against the design, and every designed point against the replay. All of
it runs on whole arrays (no loop over blocks or samples), so a program of 10⁵ blocks is
checked in about a second.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from freecad_conformal.errors import PostError
from freecad_conformal.post.gcode_reader import read_joints
from freecad_conformal.post.kinematics import forward, head_offset
from freecad_conformal.post.machine import Machine
from freecad_conformal.post.nearest import (
    arc_length_guess, near_guess, nearest_poses, nearest_where_it_matters)
from freecad_conformal.toolpath import Toolpath
from freecad_conformal.tolerances import DIVISION_GUARD

#: The replay's polyline stays this close to the true path of every block (mm, rad):
#: a tenth of the default tolerances, so sampling hides nothing the check is about.
SAMPLE_RESOLUTION = 1e-3
ANGLE_RESOLUTION = 1e-4
#: No sample step turns a rotary axis more than this (rad), whatever the lever.
ANGLE_STEP = 0.05
MAX_SAMPLES_PER_BLOCK = 100_000

#: More replay samples than this would not fit in memory: the program is refused.
MAX_SAMPLES = 30_000_000


@dataclass(frozen=True)
class Deviation:
    """Largest tool-tip distance (mm) and tool-axis angle (rad) between replay and design."""

    position: float
    angle: float
    blocks: int
    samples: int

    def report(self) -> str:
        return (f"{self.blocks} blocks, {self.samples} samples: largest position deviation "
                f"{self.position:.6f} mm, largest angle deviation {math.degrees(self.angle):.6f} deg")


def read_program(text: str, machine: Machine) -> np.ndarray:
    """Joint targets (mm, rad) of every G0/G1 block, starting with the first one."""
    return read_program_tools(text, machine)[0]


def read_program_tools(text: str, machine: Machine) -> tuple[np.ndarray, np.ndarray]:
    """Joint targets as `read_program`, and the tool each block runs with (-1: none yet)."""
    joints, _, tools = read_joints(text, machine.joint_names)
    return _unwrap_like_controller(machine, joints), tools


def forward_by_tool(machine: Machine, joints: np.ndarray,
                    tools: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """Forward kinematics with each row's tool (head pivots from that tool's tip)."""
    if tools is None or not machine.head_axes or not machine.tool_lengths:
        return forward(machine, joints)
    tips, axes = np.empty((len(joints), 3)), np.empty((len(joints), 3))
    for tool in np.unique(tools).tolist():
        rows = tools == tool
        # before any T word the head pivots are the machine file's own (the reference tool)
        used = machine.for_tool(tool) if tool >= 0 else dataclasses.replace(machine, tool_lengths=())
        tips[rows], axes[rows] = forward(used, joints[rows])
    return tips, axes


def _unwrap_like_controller(machine: Machine, joints: np.ndarray) -> np.ndarray:
    """Wrapped rotary axes take the short way; make them continuous before interpolating."""
    out = joints.copy()
    for k, axis in enumerate(machine.rotary):
        if axis.wrap:
            out[:, 3 + k] = np.unwrap(out[:, 3 + k])
    return out


def sample_counts(machine: Machine, joints: np.ndarray, tools: np.ndarray | None = None):
    """Samples per block so that the polyline through them is within SAMPLE_RESOLUTION of
    the block's true (joint-linear) path; also the tips and axes at the blocks' ends.

    A smooth block strays from its chord by about its midpoint sag, and from a polyline of
    k equal parts by sag / k²; a block that winds far (a full turn has no sag at its
    midpoint) is also cut so each part turns the tip less than the arc whose sagitta is the
    resolution at the tip's largest lever about the rotary axes.
    """
    delta = np.diff(joints, axis=0)
    tips, axes = forward_by_tool(machine, joints, tools)
    middle, middle_axes = forward_by_tool(machine, joints[:-1] + 0.5 * delta,
                                          None if tools is None else tools[1:])
    sag = np.linalg.norm(middle - 0.5 * (tips[:-1] + tips[1:]), axis=1)
    blended = axes[:-1] + axes[1:]
    blended /= np.maximum(np.linalg.norm(blended, axis=1), DIVISION_GUARD)[:, None]
    sag_angle = np.arccos(np.clip(np.einsum("ij,ij->i", middle_axes, blended), -1.0, 1.0))
    counts = np.maximum(np.sqrt(sag / SAMPLE_RESOLUTION), np.sqrt(sag_angle / ANGLE_RESOLUTION))
    if machine.rotary:
        machine_tip = joints[:, :3] + head_offset(machine, joints)
        lever = np.linalg.norm(machine_tip, axis=1)
        lever = (np.maximum(lever[:-1], lever[1:]) + np.linalg.norm(delta[:, :3], axis=1)
                 + sum(np.linalg.norm(a.pivot) for a in machine.rotary))
        step = 2.0 * np.sqrt(2.0 * SAMPLE_RESOLUTION / np.maximum(lever, SAMPLE_RESOLUTION))
        turned = np.abs(delta[:, 3:]).sum(axis=1)
        counts = np.maximum(counts, turned / np.minimum(step, ANGLE_STEP))
    return np.clip(np.ceil(counts), 1, MAX_SAMPLES_PER_BLOCK).astype(np.int64), tips, axes


def replay(machine: Machine, joints: np.ndarray,
           tools: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Sample every block in joint space; return part-frame tips and axes along the path
    (each block with the tool it runs with, when `tools` gives one per row)."""
    delta = np.diff(joints, axis=0)
    counts, tips, axes = sample_counts(machine, joints, tools)
    if tools is not None and machine.head_axes and machine.tool_lengths:
        # the move after a tool change starts from the new tool's tip wherever the change
        # left the head: a repositioning, not part of the path (only its end is checked)
        counts[tools[1:] != tools[:-1]] = 1
    if counts.sum() > MAX_SAMPLES:
        raise PostError(f"replaying the program would take {int(counts.sum()):,} samples (more "
                        f"than {MAX_SAMPLES:,}); its blocks move too far")
    ends = np.cumsum(counts)                      # sample index of every block's end
    out_tips = np.empty((int(ends[-1]) + 1, 3))
    out_axes = np.empty_like(out_tips)
    out_tips[0], out_axes[0] = tips[0], axes[0]
    out_tips[ends], out_axes[ends] = tips[1:], axes[1:]   # block ends: already known
    inner = counts - 1
    block = np.repeat(np.arange(len(delta)), inner)
    if len(block):
        step = np.arange(len(block)) - np.repeat(np.cumsum(inner) - inner, inner) + 1
        s = step / counts[block]
        rows = ends[block] - counts[block] + step
        inner_tools = None if tools is None else tools[block + 1]
        out_tips[rows], out_axes[rows] = forward_by_tool(
            machine, joints[block] + s[:, None] * delta[block], inner_tools)
    return out_tips, out_axes


def polyline_deviation(samples: np.ndarray, sample_axes: np.ndarray, path: np.ndarray,
                       path_axes: np.ndarray) -> tuple[float, float]:
    """Largest distance and axis angle from samples to their best match on a polyline."""
    distance, angle, _ = nearest_poses(samples, sample_axes, path, path_axes)
    return float(distance.max()), float(angle.max())


def verify_program(text: str, machine: Machine, toolpath: Toolpath) -> Deviation:
    """Replay `text` on `machine` and compare with `toolpath` (both directions).

    The way back (every designed point against the replay) starts from the samples matched
    to the designed moves on the way there; only points that land farther than the way
    there's largest deviation are searched for in full, since only they can raise it.
    """
    joints, tools = read_program_tools(text, machine)
    tips, axes = replay(machine, joints, tools)
    design, design_axes = toolpath.points, toolpath.axes
    if len(tips) >= 2 and len(design) >= 2:
        distance, angle, matched = nearest_where_it_matters(
            tips, axes, design, design_axes, arc_length_guess(tips, design))
    else:
        distance, angle, matched = nearest_poses(tips, axes, design, design_axes)
    there = (float(distance.max()), float(angle.max()))
    if len(tips) < 2:
        back = polyline_deviation(design, design_axes, tips, axes)
        return Deviation(max(there[0], back[0]), max(there[1], back[1]), len(joints), len(tips))
    order = np.argsort(matched, kind="stable")
    first = np.searchsorted(matched[order], np.arange(len(design)) - 1)
    guess = order[np.clip(first, 0, len(order) - 1)]
    back_distance, back_angle, _ = near_guess(design, design_axes, tips, axes, guess)
    unsure = np.flatnonzero((back_distance > there[0]) | (back_angle > there[1]))
    if len(unsure):
        exact = nearest_poses(design[unsure], design_axes[unsure], tips, axes)
        back_distance[unsure], back_angle[unsure] = exact[0], exact[1]
    return Deviation(max(there[0], float(back_distance.max())), max(there[1], float(back_angle.max())),
                     len(joints), len(tips))


def verify_file(path: str | Path, machine: Machine, toolpath: Toolpath) -> Deviation:
    source = Path(path)
    if not source.is_file():
        raise PostError(f"program file {source} "
                        f"{'is a folder' if source.is_dir() else 'does not exist'}")
    return verify_program(source.read_text(encoding="utf-8", errors="replace"), machine, toolpath)
