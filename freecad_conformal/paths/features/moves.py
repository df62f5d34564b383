"""Moves between cures that stay clear of what is built: up, across above it, down.

A travel from the end of one cure to the start of the next retracts along the tool axis to
`lift` mm above the face, follows the face offset by `lift` (the straight line between the
two points' surface parameters, mapped back onto the face and pushed out along its normal,
so the move bends with the surface instead of cutting a chord through it), and comes down
the next axis. `lift` is the height of what is built plus a clearance. Tool changes retract
`HOME_LIFT` mm along the axis first (the tool goes home), then come back the same way.
"""
from __future__ import annotations

import math

import numpy as np

from freecad_conformal.geometry.faces import normals_at, parameters_of, points_at
from freecad_conformal.toolpath import ToolpathBuilder
from freecad_conformal.tolerances import COINCIDENT_POINTS

#: Clearance (mm) above the highest built material for travels.
TRAVEL_CLEARANCE = 2.0
#: Retract (mm) along the tool axis before a tool change.
HOME_LIFT = 20.0
#: Offset-surface travels are sampled at least this often (mm).
TRAVEL_STEP = 1.0


def _short_way(face, uv0: np.ndarray, uv1: np.ndarray) -> np.ndarray:
    """uv1 moved by a period so the parameter line takes the short way round a closed face."""
    out = uv1.copy()
    surface = face.Surface
    for k, periodic in enumerate((surface.isUPeriodic(), surface.isVPeriodic())):
        if periodic:
            period = surface.UPeriod() if k == 0 else surface.VPeriod()
            out[k] -= period * round((out[k] - uv0[k]) / period)
    return out


def offset_travel(face, start: np.ndarray, end: np.ndarray, lift: float) -> tuple[np.ndarray, np.ndarray]:
    """Points and axes from above `start` to above `end` on the face offset by `lift`."""
    uv = parameters_of(face, np.vstack([start, end]))
    uv1 = _short_way(face, uv[0], uv[1])
    feet = points_at(face, np.vstack([uv[0], uv1]))
    length = float(np.linalg.norm(feet[1] - feet[0])) + COINCIDENT_POINTS
    count = max(int(math.ceil(length * (1.0 + lift / 5.0) / TRAVEL_STEP)), 1) + 1
    t = np.linspace(0.0, 1.0, count)[:, None]
    line = (1 - t) * uv[0] + t * uv1
    normals = normals_at(face, line)
    return points_at(face, line) + lift * normals, normals


def travel(builder: ToolpathBuilder, face, start: np.ndarray, start_axis: np.ndarray,
           end: np.ndarray, end_axis: np.ndarray, lift: float, feed: float, tool: int) -> None:
    """Retract from `start`, travel above the face, come down onto `end` (one travel segment)."""
    across, axes = offset_travel(face, start, end, lift)
    # the first piece rises from `start` along the face normal; the last comes down onto `end`
    ijk = np.vstack([np.asarray(start_axis, dtype=float)[None, :], axes[1:], end_axis])
    builder.add_segment(np.vstack([across, end]), ijk, kind="travel", feed=feed, tool=tool)


def approach(builder: ToolpathBuilder, point: np.ndarray, axis: np.ndarray, lift: float,
             feed: float, tool: int) -> None:
    """Come down `axis` from `lift` mm above onto `point`."""
    builder.add_segment([point + lift * axis, point], axes=axis, kind="travel", feed=feed, tool=tool)


def retract(builder: ToolpathBuilder, point: np.ndarray, axis: np.ndarray, lift: float,
            feed: float, tool: int) -> None:
    builder.add_segment([point + lift * axis], axes=axis, kind="travel", feed=feed, tool=tool)
