"""Shells built by rotation (METHODS section 1, steps 1–6) and the inverse conical cup.

Base shell: on a sphere, cylinder or cone face (surfaces of revolution: OCC's u runs round the
axis, v along the meridian) the large tool cures one ring per full rotation: tilt to the
ring's normal, light on, rotate C once, light off, next ring `width` further along the
meridian (the spacing measured on the surface: Δv = width / |∂S/∂v|). Layers stack along the
normal, `layer` mm apart. The tool axis is the outward normal, or tilted from it by `tilt`
(rad) in the meridian plane. Every ring's tilt from the build direction must be one the
tool reaches (its W, or the band of an angled head): otherwise PlanError naming the ring.

Inverse conical cup: a wall grown upward along a cone, one ring (a full C rotation) per
layer at one height, the tool inclined at the cone angle (along the cone's generator); the
first layer is special (its own height and feed: it bonds to the base), 1 mm layers after.
METHODS gives no first-layer values: 0.5 mm at half the feed is this module's choice.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from freecad_conformal.errors import PlanError
from freecad_conformal.geometry.faces import face_kind, normals_at, points_at
from freecad_conformal.paths.features.moves import approach, retract, travel
from freecad_conformal.process.selection import TILT_TOLERANCE
from freecad_conformal.process.tools import Tool
from freecad_conformal.tolerances import DEFAULT_LINEAR_TOLERANCE, ROUNDING_SLACK
from freecad_conformal.toolpath import ToolpathBuilder

REVOLVED = ("sphere", "cylinder", "cone")
FIRST_LAYER_HEIGHT = 0.5
FIRST_LAYER_FEED_FACTOR = 0.5


@dataclass
class RingPath:
    """One full rotation: points (n, 3) closed, tool axes (n, 3), its layer and tilt."""

    points: np.ndarray
    axes: np.ndarray
    layer: int
    tilt: float
    feed: float


def ring_samples(radius: float, tolerance: float = DEFAULT_LINEAR_TOLERANCE) -> int:
    """Points on a full circle of `radius` so each chord stays within `tolerance`."""
    step = 2.0 * math.acos(max(1.0 - tolerance / max(radius, tolerance), -1.0))
    return max(int(math.ceil(2 * math.pi / step)), 8) + 1


def check_tilt(axes: np.ndarray, tool: Tool, build_direction, what: str) -> float:
    """Largest tilt (rad) of `axes` from the build direction; PlanError beyond the tool's reach."""
    up = np.asarray(build_direction, dtype=float) / np.linalg.norm(build_direction)
    tilts = np.arccos(np.clip(axes @ up, -1.0, 1.0))
    low, high = tool.reachable_tilt()
    bad = (tilts > high + TILT_TOLERANCE) | (tilts < low - TILT_TOLERANCE)
    if np.any(bad):
        worst = float(tilts[np.argmax(bad)])
        raise PlanError(f"{what}: the tool must tilt {math.degrees(worst):.1f}°, beyond what "
                        f"{tool.id} reaches ({math.degrees(low):.1f}°..{math.degrees(high):.1f}°, "
                        f"W {math.degrees(tool.max_tilt):g}°)")
    return float(tilts.max())


def tilt_axes(normals: np.ndarray, meridians: np.ndarray, tilt: float) -> np.ndarray:
    """Normals turned by `tilt` (rad) towards the meridian tangents (in the meridian plane)."""
    if tilt == 0.0:
        return normals
    out = math.cos(tilt) * normals + math.sin(tilt) * meridians
    return out / np.linalg.norm(out, axis=1)[:, None]


def _meridians(face, uv: np.ndarray) -> np.ndarray:
    rows = []
    for u, v in uv:
        d = face.Surface.getDN(float(u), float(v), 0, 1)
        rows.append((d.x, d.y, d.z))
    m = np.array(rows)
    return m / np.linalg.norm(m, axis=1)[:, None]


def base_shell(face, tool: Tool, width: float, layers: int = 1, layer: float = 1.0,
               feed: float = 24.0, tilt: float = 0.0, build_direction=(0, 0, 1),
               what: str = "shell") -> list[RingPath]:
    """Rings over a sphere/cylinder/cone face, `width` apart on the surface, `layers` deep."""
    kind = face_kind(face)
    if kind not in REVOLVED:
        raise PlanError(f"{what}: a shell by rotation needs a sphere, cylinder or cone face, "
                        f"not a {kind}")
    if not (width > 0 and layer > 0 and layers >= 1):
        raise PlanError(f"{what}: width {width!r}, layer {layer!r} must be > 0 and layers >= 1")
    u0, u1, v0, v1 = face.ParameterRange
    if u1 - u0 < 2 * math.pi - ROUNDING_SLACK:
        raise PlanError(f"{what}: the face does not go all the way round its axis "
                        f"({math.degrees(u1 - u0):.1f}°): a ring needs a full rotation")
    metric = float(np.linalg.norm(np.array(tuple(face.Surface.getDN(u0, 0.5 * (v0 + v1), 0, 1)))))
    step = width / metric
    count = int(math.floor((v1 - v0) / step))
    if count < 1:
        raise PlanError(f"{what}: the face is {(v1 - v0) * metric:.3g} mm along its meridian, "
                        f"narrower than one {width:g} mm ring")
    vs = v0 + step * (np.arange(count) + 0.5) + 0.5 * ((v1 - v0) - count * step)
    rings: list[RingPath] = []
    for k in range(layers):
        offset = (k + 0.5) * layer
        for i, v in enumerate(vs):
            centre_radius = _ring_radius(face, v) + offset
            n = ring_samples(centre_radius)
            uv = np.column_stack((np.linspace(u0, u0 + 2 * math.pi, n), np.full(n, v)))
            normals = normals_at(face, uv)
            axes = tilt_axes(normals, _meridians(face, uv), tilt)
            points = points_at(face, uv) + offset * normals
            ring_tilt = check_tilt(axes, tool, build_direction, f"{what} layer {k + 1} ring {i + 1}")
            rings.append(RingPath(points, axes, k, ring_tilt, feed))
    return rings


def _ring_radius(face, v: float) -> float:
    p = np.array(tuple(face.valueAt(0.0, float(v))))
    s = face.Surface
    axis = np.array(tuple(s.Axis))
    centre = np.array(tuple(s.Center if hasattr(s, "Center") else s.Apex))
    w = p - centre
    return float(np.linalg.norm(w - (w @ axis) * axis))


def conical_cup(face, tool: Tool, height: float, layer: float = 1.0, feed: float = 24.0,
                first_layer: float = FIRST_LAYER_HEIGHT,
                first_feed: float | None = None, build_direction=(0, 0, 1),
                what: str = "conical cup", width: float = 0.0) -> list[RingPath]:
    """A wall `height` mm tall grown up a cone face: ring k at height z_k along the cone
    axis (first layer `first_layer`, then `layer` each), tool along the cone's generator.
    The face is one side of a wall `width` mm thick: the rings run `width`/2 inside the
    material (against the face's outward normal), i.e. on the wall's centre."""
    if face_kind(face) != "cone":
        raise PlanError(f"{what}: needs a cone face, not a {face_kind(face)}")
    if not (height > 0 and layer > 0 and first_layer > 0):
        raise PlanError(f"{what}: height, layer and first layer must be > 0 mm")
    surface = face.Surface
    axis = np.array(tuple(surface.Axis))
    alpha = float(surface.SemiAngle)
    u0, u1, v0, v1 = face.ParameterRange
    # v is the slant length: a height z along the axis is v = z / cos α above v0
    heights = [first_layer] + list(first_layer + layer * np.arange(1, int(
        math.floor((height - first_layer) / layer + ROUNDING_SLACK)) + 1))
    rings: list[RingPath] = []
    for k, z in enumerate(heights):
        v = v0 + (z - (first_layer if k == 0 else layer) / 2.0) / math.cos(alpha)
        if v > v1 + ROUNDING_SLACK:
            raise PlanError(f"{what}: layer {k + 1} at {z:g} mm is above the cone face "
                            f"({(v1 - v0) * math.cos(alpha):.3g} mm tall)")
        uv = np.column_stack((np.linspace(u0, u0 + 2 * math.pi, ring_samples(_ring_radius(face, v))),
                              np.full(ring_samples(_ring_radius(face, v)), v)))
        generators = _meridians(face, uv)
        generators *= np.sign(generators @ axis)[:, None]
        ring_tilt = check_tilt(generators, tool, build_direction, f"{what} layer {k + 1}")
        this_feed = (feed * FIRST_LAYER_FEED_FACTOR if first_feed is None else first_feed) if k == 0 else feed
        centre = points_at(face, uv) - 0.5 * width * normals_at(face, uv)
        rings.append(RingPath(centre, generators, k, ring_tilt, this_feed))
    return rings


def rings_toolpath(rings: list[RingPath], tool_number: int = 0, power: float = 1.0,
                   travel_feed: float = 600.0, lift: float = 2.0,
                   builder: ToolpathBuilder | None = None, face=None,
                   power_w: float = 0.0) -> ToolpathBuilder:
    """Steps 2–6 per ring: come in along the axis, light on, one full rotation, light off;
    between rings travel `lift` mm above the face (moves.travel) or, without a face (the
    cup, whose next ring is straight up the tool axis), move straight to the next start.
    Each cure carries its energy per mm, `power_w`/v (J/mm)."""
    builder = builder or ToolpathBuilder(part="shell", material="UV resin")
    previous = None
    for ring in rings:
        start, axis = ring.points[0], ring.axes[0]
        if previous is None:
            approach(builder, start, axis, lift, travel_feed, tool_number)
        elif face is not None:
            travel(builder, face, previous.points[-1], previous.axes[-1], start, axis, lift,
                   travel_feed, tool_number)
        else:
            builder.add_segment([start], axes=axis, kind="travel", feed=travel_feed,
                                tool=tool_number)
        builder.event("light_on", power=power)
        builder.add_segment(ring.points, ring.axes, kind="cure", feed=ring.feed, tool=tool_number,
                            flow=power_w / (ring.feed / 60.0) if power_w else 0.0)
        builder.event("light_off")
        previous = ring
    if previous is not None:
        retract(builder, previous.points[-1], previous.axes[-1], lift, travel_feed, tool_number)
    return builder
