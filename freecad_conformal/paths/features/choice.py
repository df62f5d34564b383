"""The tool for a feature on a face, by the curvature rules, resolution and reach.

METHODS section 1: with rs the face's smallest radius of curvature, cd the curing depth (the
layer) and θ the largest rotation the feature needs from the build direction, a straight
tool fits when dt ≤ 2·sqrt(cd·(2·rs − cd)) and dt ≤ 2·(rs − cd)·sin θ, and θ must lie in the
tilt range the tool reaches (an angled head where a straight one cannot tilt far enough).
Of the tools that fit, the largest that resolves the finest width asked is chosen
(process/selection.choose_tool); the reason is kept for the program header.

θ is the largest tilt of the face's normals over a grid on the face (or of the given axes),
at least `MIN_THETA`: the published second rule rejects every tool at θ = 0 exactly, which
would leave nothing for a flat-topped feature.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from freecad_conformal.errors import PlanError
from freecad_conformal.geometry.faces import domain_grid, normals_at, smallest_radius
from freecad_conformal.process.selection import choose_tool
from freecad_conformal.process.tools import Tool

#: Smallest rotation used in the second rule (rad): a flat feature still needs some tool.
MIN_THETA = math.radians(1.0)
#: Grid for the face's tilt range (per direction).
TILT_GRID = 24


@dataclass(frozen=True)
class FaceToolChoice:
    tool: Tool
    reason: str
    rs: float
    theta: float


def face_tilt(face, build_direction, axes: np.ndarray | None = None) -> float:
    """Largest angle (rad) between the build direction and the face normals (or `axes`)."""
    up = np.asarray(build_direction, dtype=float)
    up = up / np.linalg.norm(up)
    if axes is None:
        axes = normals_at(face, domain_grid(face, TILT_GRID))
    return float(np.max(np.arccos(np.clip(np.asarray(axes) @ up, -1.0, 1.0))))


def choose_for_face(face, tools: list[Tool], cd: float, resolution: float | None,
                    build_direction=(0.0, 0.0, 1.0), axes: np.ndarray | None = None,
                    what: str = "feature") -> FaceToolChoice:
    """The tool for curing `cd` mm layers on `face` (PlanError with every tool's reason)."""
    rs = smallest_radius(face)
    theta = max(face_tilt(face, build_direction, axes), MIN_THETA)
    if math.isfinite(rs) and cd >= rs:
        raise PlanError(f"{what}: the layer {cd:g} mm is not smaller than the face's smallest "
                        f"radius of curvature {rs:.4g} mm")
    choice = choose_tool(tools, rs, cd, theta, resolution=resolution)
    if choice.recommended is None:
        raise PlanError(f"{what}: no tool fits: {choice.explanation()}")
    tool = choice.recommended
    limits = ("flat face: no curvature limit" if not math.isfinite(rs) else
              f"rs {rs:.4g} mm: dt <= {choice.reach_limit:.3g} (reach) and "
              f"<= {choice.rotation_limit:.3g} (rotation)")
    left_out = ", ".join(f"{tid} ({why})" for tid, why in sorted(choice.reasons.items()))
    reason = (f"{tool.id} (dt {tool.diameter:g} mm, {tool.head} head) for tilt up to "
              f"{math.degrees(theta):.1f}°, cd {cd:g} mm, {limits}"
              + (f", resolution {resolution:g} mm" if resolution else "")
              + (f"; not {left_out}" if left_out else ""))
    return FaceToolChoice(tool, reason, rs, theta)
