"""Independent check of an emitted program: read it back, replay it through forward
kinematics and measure how far the tool strays from the designed toolpath.

The reader knows only G-code (absolute G0/G1 with the machine's axis words, comments in
parentheses or after ';'); it shares no state with the post. Each block is sampled in joint
space (the controller interpolates joints linearly), mapped to tool-tip poses in the part
frame, and compared with the designed polyline both ways: every replayed sample against the
design, and every designed point against the replay.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from freecad_conformal.errors import PostError
from freecad_conformal.post.kinematics import forward
from freecad_conformal.post.linearize import ZERO_CHORD, slerp
from freecad_conformal.post.machine import Machine
from freecad_conformal.toolpath import Toolpath

_WORD = re.compile(r"([A-Z])\s*([-+]?(?:\d+\.?\d*|\.\d+))")

#: Replay samples per mm of block motion (tip mm or rad × 10): fine enough that sampling
#: cannot hide a deviation larger than the tolerances the post works to.
SAMPLES_PER_MM = 4.0
MAX_SAMPLES_PER_BLOCK = 100_000

#: Probes per block to measure its tip path length (a block may wind many turns).
LENGTH_PROBES = 64

#: Probes along a pure reorientation's arc of axes (1/64 of a 30° turn is under 0.5°·¼).
ARC_PROBES = 257

#: Matching a sample to the design weighs the axis angle as tip motion at this lever (mm
#: per rad, about a tool's length), so where the tip stands still the axis decides.
POSE_LEVER = 50.0

#: Candidate designed moves looked at around the cursor when matching samples in order.
WINDOW = 512


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
    names = machine.joint_names
    current = [math.nan] * len(names)
    targets: list[list[float]] = []
    motion = None
    for number, raw in enumerate(text.splitlines(), start=1):
        line = re.sub(r"\([^)]*\)", "", raw.split(";", 1)[0]).upper()
        words = _WORD.findall(line)
        codes = {float(v) for letter, v in words if letter == "G"}
        if codes & {0.0, 1.0}:
            motion = "move"
        elif codes & {2.0, 3.0}:
            raise PostError(f"line {number}: arcs (G2/G3) are not replayed: {raw.strip()}")
        elif codes & {91.0}:
            raise PostError(f"line {number}: relative positioning (G91) is not replayed")
        axis_words = [(letter, float(v)) for letter, v in words if letter in names]
        if not axis_words or motion is None or codes & {4.0, 92.0}:
            continue
        for letter, value in axis_words:
            k = names.index(letter)
            current[k] = value if k < 3 else math.radians(value)
        targets.append(list(current))
    joints = np.array(targets, dtype=float).reshape(-1, len(names))
    if len(joints) == 0:
        raise PostError("the program has no G0/G1 move for the machine's axes")
    if np.isnan(joints[0]).any():
        missing = [n for n, v in zip(names, joints[0]) if math.isnan(v)]
        raise PostError(f"the first move does not set axis/axes {', '.join(missing)}")
    return _unwrap_like_controller(machine, joints)


def _unwrap_like_controller(machine: Machine, joints: np.ndarray) -> np.ndarray:
    """Wrapped rotary axes take the short way; make them continuous before interpolating."""
    out = joints.copy()
    for k, axis in enumerate(machine.rotary):
        if axis.wrap:
            out[:, 3 + k] = np.unwrap(out[:, 3 + k])
    return out


def replay(machine: Machine, joints: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Sample every block in joint space; return part-frame tips and axes along the path."""
    delta = np.diff(joints, axis=0)
    reach = np.zeros(len(delta))
    previous, _ = forward(machine, joints[:-1])
    for s in np.arange(1, LENGTH_PROBES + 1) / LENGTH_PROBES:   # tip path length per block
        tip, _ = forward(machine, joints[:-1] + s * delta)
        reach += np.linalg.norm(tip - previous, axis=1)
        previous = tip
    reach += 10.0 * np.abs(delta[:, 3:]).sum(axis=1)
    counts = np.clip(np.ceil(reach * SAMPLES_PER_MM), 1, MAX_SAMPLES_PER_BLOCK).astype(np.int64)
    block = np.repeat(np.arange(len(delta)), counts)
    first = np.cumsum(counts) - counts
    s = (np.arange(len(block)) - first[block] + 1) / counts[block]
    samples = np.vstack([joints[:1], joints[block] + s[:, None] * delta[block]])
    return forward(machine, samples)


def polyline_deviation(samples: np.ndarray, sample_axes: np.ndarray, path: np.ndarray,
                       path_axes: np.ndarray) -> tuple[float, float]:
    """Largest distance and axis angle from ordered samples to an ordered polyline.

    A cursor walks the polyline in order (a window of WINDOW moves ahead and behind), so
    the match follows the path even where it passes near itself.
    """
    if len(path) == 1:
        distance = np.linalg.norm(samples - path[0], axis=1)
        angle = np.arccos(np.clip(sample_axes @ path_axes[0], -1.0, 1.0))
        return float(distance.max()), float(angle.max())
    a, b = path[:-1], path[1:]
    cursor, worst_distance, worst_angle = 0, 0.0, 0.0
    for point, axis in zip(samples, sample_axes):
        low, high = max(cursor - WINDOW, 0), min(cursor + WINDOW, len(a))
        chord = b[low:high] - a[low:high]
        length2 = np.maximum(np.einsum("ij,ij->i", chord, chord), 1e-300)
        t = np.clip(((point - a[low:high]) * chord).sum(axis=1) / length2, 0.0, 1.0)
        distance = np.linalg.norm(a[low:high] + t[:, None] * chord - point, axis=1)
        designed = slerp(path_axes[low:high], path_axes[low + 1:high + 1], t)
        angles = np.arccos(np.clip(designed @ axis, -1.0, 1.0))
        for j in np.flatnonzero(length2 <= ZERO_CHORD ** 2).tolist():
            angles[j] = _axis_miss(path_axes, low + j, axis)
        pick = int(np.argmin(distance + POSE_LEVER * angles))
        cursor = low + pick
        worst_distance = max(worst_distance, float(distance[pick]))
        angle = float(angles[pick])
        worst_angle = max(worst_angle, angle)
    return worst_distance, worst_angle


def _axis_miss(path_axes: np.ndarray, move: int, axis: np.ndarray) -> float:
    """Angle from `axis` to the arc of axes of a pure reorientation (the tip stands still
    while the axis turns, so any axis on that arc is on the design)."""
    params = np.linspace(0.0, 1.0, ARC_PROBES)
    designed = slerp(np.repeat(path_axes[move:move + 1], ARC_PROBES, axis=0),
                     np.repeat(path_axes[move + 1:move + 2], ARC_PROBES, axis=0), params)
    return float(np.arccos(np.clip(designed @ axis, -1.0, 1.0)).min())


def verify_program(text: str, machine: Machine, toolpath: Toolpath) -> Deviation:
    """Replay `text` on `machine` and compare with `toolpath` (both directions)."""
    joints = read_program(text, machine)
    tips, axes = replay(machine, joints)
    design, design_axes = toolpath.points, toolpath.axes
    there = polyline_deviation(tips, axes, design, design_axes)
    block_tips, block_axes = forward(machine, joints)
    back = polyline_deviation(design, design_axes, tips, axes) if len(tips) > 1 else \
        polyline_deviation(design, design_axes, block_tips, block_axes)
    return Deviation(max(there[0], back[0]), max(there[1], back[1]), len(joints), len(tips))


def verify_file(path: str | Path, machine: Machine, toolpath: Toolpath) -> Deviation:
    source = Path(path)
    if not source.is_file():
        raise PostError(f"program file {source} does not exist")
    return verify_program(source.read_text(encoding="utf-8", errors="replace"), machine, toolpath)
