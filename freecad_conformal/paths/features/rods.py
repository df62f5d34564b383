"""Rods normal to a sphere or a cylinder by point curing (METHODS section 1, steps 7–15).

Layout (design parameters θ, d, θi, βi, N; manufacturing D, R, a, l, W):
  (i)   θ ≥ atan(a / (2(R − l))) + asin(2D / sqrt(a² + 4(R − l)²))   published no-collision rule
  (ii)  θi = i·θ = i·d/R          (iii) ni = floor(2πR·sin θi / d)
  (iv)  βi = 2π / ni              (v)   N ≤ floor(W / θ)
Ring 0 is the single rod at the pole. On a cylinder (one radius infinite) rings are circles
d apart along the axis, each with floor(2πR/d) rods, and the tool tilt is the same for all.

The published rule (i) is kept as `published_min_angle`; the layout is accepted or refused by a
real collision test (`collisions`): while rod j is cured the tool's envelope (the tool
library's cone tip and cylindrical body along the rod axis, from the surface outward) must
stay clear of every rod already built, each a cylinder of diameter a and length l.

Rod diameter by speed (point curing: the tool moves along its own axis, so the exposure per
mm of rod is inversely proportional to the speed): the feed of each rod piece comes from the
tool's point-curing fit (paths/features/feeds.py, process/curing_fit.py); a diameter profile
along the rod becomes one feed per piece.

Moves between rods: retract along the rod axis to `CLEARANCE` above the rod tips, travel on
the surface offset by l + CLEARANCE (an arc round the sphere's centre or the cylinder's axis,
sampled so its chords dip less than a quarter of the clearance), then come down the next
rod's axis to its base. The whole program is then checked against the tool envelope
(paths/features/clearance.py).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from freecad_conformal.errors import PlanError
from freecad_conformal.paths.features.feeds import CureSetting
from freecad_conformal.process.tools import Tool
from freecad_conformal.toolpath import ToolpathBuilder
from freecad_conformal.tolerances import DIVISION_GUARD, ROUNDING_SLACK, ZERO_LENGTH

#: Heights (mm) between envelope samples in the collision test: 0.05 mm is far below any
#: rod diameter (>= 0.2 mm), so a contact cannot slip between two samples.
ENVELOPE_STEP = 0.05

#: Clearance (mm) above the rod tips at which the tool travels to the next rod.
CLEARANCE = 2.0


def published_min_angle(a: float, radius: float, length: float, head: float) -> float:
    """Constraint (i) as published: the smallest θ (rad) between neighbouring rods."""
    base = radius - length
    if not (a > 0 and base > 0 and head > 0):
        raise PlanError(f"rods: constraint (i) needs a > 0, R − l > 0 and D > 0 (a {a:g}, "
                        f"R {radius:g}, l {length:g}, D {head:g} mm)")
    ratio = 2.0 * head / math.sqrt(a * a + 4.0 * base * base)
    if ratio > 1.0:
        raise PlanError(f"rods: constraint (i) has no solution: tool head D {head:g} mm is too "
                        f"wide for rods of {a:g} mm on R − l = {base:g} mm")
    return math.atan(a / (2.0 * base)) + math.asin(ratio)


@dataclass(frozen=True)
class Ring:
    index: int
    tilt: float          # θi: angle of the ring's rods from the pole direction (rad)
    count: int           # ni
    step: float          # βi (rad)
    offset: float = 0.0  # axial position (cylinder only, mm)


@dataclass
class RodLayout:
    """Rings of rods on a sphere or cylinder and every rod's base point and axis."""

    surface: str
    radius: float
    spacing: float              # d
    angle: float                # θ (sphere) or 2π/n (cylinder, within a ring)
    diameter: float             # a
    length: float               # l
    rings: list[Ring]
    bases: np.ndarray = field(repr=False)    # (n, 3)
    axes: np.ndarray = field(repr=False)     # (n, 3) unit outward normals
    ring_of: np.ndarray = field(repr=False)  # (n,)
    centre: np.ndarray | None = field(default=None, repr=False)  # sphere centre / axis point
    axis: np.ndarray | None = field(default=None, repr=False)    # cylinder axis (unit)

    def foot(self, normal: np.ndarray, along: float = 0.0) -> np.ndarray:
        """The surface point whose outward normal is `normal` (cylinder: at `along` mm)."""
        centre = np.zeros(3) if self.centre is None else self.centre
        if self.surface == "cylinder" and self.axis is not None:
            return centre + along * self.axis + self.radius * normal
        return centre + self.radius * normal


def _frame(axis: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    seed = np.eye(3)[int(np.argmin(np.abs(axis)))]
    u = seed - (seed @ axis) * axis
    u /= np.linalg.norm(u)
    return u, np.cross(axis, u)


def sphere_layout(center, pole, radius: float, spacing: float, diameter: float, length: float,
                  max_tilt: float, rings: int | None = None) -> RodLayout:
    """Rings (ii)–(v) on a sphere: θ = d/R, N = floor(W/θ) rings unless fewer are asked."""
    if not (radius > 0 and spacing > 0 and diameter > 0 and length > 0):
        raise PlanError(f"rods: R {radius!r}, d {spacing!r}, a {diameter!r}, l {length!r} must be > 0")
    theta = spacing / radius
    limit = int(math.floor(max_tilt / theta + ROUNDING_SLACK))
    if rings is not None and rings > limit:
        raise PlanError(f"rods: {rings} rings need a tilt of {math.degrees(rings * theta):.1f}°, "
                        f"beyond the tool's W {math.degrees(max_tilt):.1f}° (constraint (v) allows "
                        f"N <= {limit})")
    count = limit if rings is None else rings
    pole = np.asarray(pole, dtype=float) / np.linalg.norm(pole)
    u, v = _frame(pole)
    out_rings, normals, ring_of = [Ring(0, 0.0, 1, 2 * math.pi)], [pole], [0]
    for i in range(1, count + 1):
        ti = i * theta
        ni = int(math.floor(2 * math.pi * radius * math.sin(ti) / spacing))
        if ni < 1:
            continue
        beta = 2 * math.pi / ni
        out_rings.append(Ring(i, ti, ni, beta))
        for k in range(ni):
            normals.append(math.cos(ti) * pole + math.sin(ti) * (math.cos(k * beta) * u
                                                                   + math.sin(k * beta) * v))
            ring_of.append(i)
    axes = np.array(normals)
    return RodLayout("sphere", radius, spacing, theta, diameter, length, out_rings,
                     np.asarray(center, dtype=float) + radius * axes, axes, np.array(ring_of),
                     np.asarray(center, dtype=float))


def cylinder_layout(origin, axis, radius: float, spacing: float, diameter: float, length: float,
                    start: float, stop: float) -> RodLayout:
    """Rings d apart along the cylinder axis from `start` to `stop` (mm), floor(2πR/d) rods each."""
    if not (radius > 0 and spacing > 0 and diameter > 0 and length > 0):
        raise PlanError(f"rods: R {radius!r}, d {spacing!r}, a {diameter!r}, l {length!r} must be > 0")
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    u, v = _frame(axis)
    n = int(math.floor(2 * math.pi * radius / spacing))
    beta = 2 * math.pi / n
    positions = np.arange(start, stop + ROUNDING_SLACK, spacing)
    if len(positions) == 0 or n < 1:
        raise PlanError(f"rods: a cylinder of radius {radius:g} mm and length {stop - start:g} mm "
                        f"holds no rod {spacing:g} mm apart")
    rings, bases, normals, ring_of = [], [], [], []
    for i, z in enumerate(positions):
        rings.append(Ring(i, math.pi / 2, n, beta, float(z)))
        for k in range(n):
            normal = math.cos(k * beta) * u + math.sin(k * beta) * v
            normals.append(normal)
            bases.append(np.asarray(origin, dtype=float) + z * axis + radius * normal)
            ring_of.append(i)
    return RodLayout("cylinder", radius, spacing, beta, diameter, length, rings, np.array(bases),
                     np.array(normals), np.array(ring_of), np.asarray(origin, dtype=float), axis)


def _segment_distance(points: np.ndarray, start: np.ndarray, end: np.ndarray) -> np.ndarray:
    chord = end - start
    t = np.clip((points - start) @ chord / max(float(chord @ chord), DIVISION_GUARD), 0.0, 1.0)
    return np.linalg.norm(points - (start + np.outer(t, chord)), axis=1)


def collisions(layout: RodLayout, tool: Tool, order: np.ndarray | None = None,
               limit: int | None = None) -> list[tuple[int, int, float]]:
    """(rod being built, rod already built, overlap mm) for every contact of the tool's
    envelope with an earlier rod, building in `order` (default: layout order); stops after
    `limit` contacts when given."""
    order = np.arange(len(layout.bases)) if order is None else np.asarray(order)
    env = tool.envelope
    heights = np.arange(0.0, env.tip_length + env.body_length + ENVELOPE_STEP, ENVELOPE_STEP)
    radii = np.array([env.radius_at(h) for h in heights])
    found = []
    reach = env.tip_length + env.body_length + layout.length + env.body_diameter + layout.diameter
    for position, j in enumerate(order.tolist()):
        built = order[:position]
        near = built[np.linalg.norm(layout.bases[built] - layout.bases[j], axis=1) <= reach]
        samples = layout.bases[j] + np.outer(heights, layout.axes[j])
        for k in near.tolist():
            distance = _segment_distance(samples, layout.bases[k],
                                         layout.bases[k] + layout.length * layout.axes[k])
            overlap = float(np.max(radii + layout.diameter / 2.0 - distance))
            if overlap > 0.0:
                found.append((j, k, overlap))
                if limit is not None and len(found) >= limit:
                    return found
    return found


def check_layout(layout: RodLayout, tool: Tool, what: str = "rods") -> None:
    """PlanError naming the first pair of colliding rods (and rule (i) for comparison)."""
    hits = collisions(layout, tool, limit=1)
    if hits:
        j, k, overlap = hits[0]
        raise PlanError(f"{what}: the {tool.id} envelope building rod {j} (ring "
                        f"{layout.ring_of[j]}) hits rod {k} (ring {layout.ring_of[k]}) by "
                        f"{overlap:.3f} mm; space the rods further "
                        f"apart (d {layout.spacing:g} mm) or shorten them (l {layout.length:g} mm)")


def _slerp(n0: np.ndarray, n1: np.ndarray, t: np.ndarray) -> np.ndarray:
    angle = math.acos(float(np.clip(n0 @ n1, -1.0, 1.0)))
    if angle < ZERO_LENGTH:
        return np.repeat(n0[None, :], len(t), axis=0)
    return (np.outer(np.sin((1 - t) * angle), n0) + np.outer(np.sin(t * angle), n1)) / math.sin(angle)


def travel_between(layout: RodLayout, j: int, k: int, clearance: float = CLEARANCE) -> tuple[np.ndarray, np.ndarray]:
    """Points and axes from above rod j's tip to rod k's base: an arc on the surface offset
    by l + clearance, then down rod k's axis."""
    lift = layout.radius + layout.length + clearance
    n0, n1 = layout.axes[j], layout.axes[k]
    angle = math.acos(float(np.clip(n0 @ n1, -1.0, 1.0)))
    # chord sagitta lift·(1 − cos(δ/2)) within a quarter of the clearance
    step = 2.0 * math.acos(max(1.0 - clearance / (4.0 * lift), -1.0))
    t = np.linspace(0.0, 1.0, max(int(math.ceil(angle / step)), 1) + 1)
    normals = _slerp(n0, n1, t)
    if layout.surface == "cylinder" and layout.axis is not None and layout.centre is not None:
        along0 = float((layout.bases[j] - layout.centre) @ layout.axis)
        along1 = float((layout.bases[k] - layout.centre) @ layout.axis)
        feet = np.array([layout.foot(n, a) for n, a in zip(normals, along0 + t * (along1 - along0))])
    else:
        feet = np.array([layout.foot(n) for n in normals])
    arc = feet + (lift - layout.radius) * normals
    points = np.vstack([arc, layout.bases[k][None, :]])
    return points, np.vstack([normals, n1[None, :]])


def rods_toolpath(layout: RodLayout, tool: Tool, settings: list[CureSetting], tool_number: int = 1,
                  travel_feed: float = 600.0, max_power: float | None = None,
                  builder: ToolpathBuilder | None = None,
                  clearance: float = CLEARANCE) -> ToolpathBuilder:
    """Steps 9–15: for each rod, come down its axis to the base, light on, move along the
    normal for l (one piece per setting: a diameter profile from base to tip, each at its
    own feed), light off, retract to the clearance and travel to the next rod above the tips."""
    if not settings:
        raise PlanError("rods: no cure setting (diameter) given")
    builder = builder or ToolpathBuilder(part="rods", material="UV resin")
    pieces = np.linspace(0.0, layout.length, len(settings) + 1)
    top = layout.length + clearance
    power = settings[0].power / (max_power or settings[0].power)
    for index, (base, axis) in enumerate(zip(layout.bases, layout.axes)):
        if index == 0:
            builder.add_segment([base + top * axis, base], axes=axis, kind="travel",
                                feed=travel_feed, tool=tool_number)
        else:
            points, axes = travel_between(layout, index - 1, index, clearance)
            builder.add_segment(points, axes, kind="travel", feed=travel_feed, tool=tool_number)
        builder.event("light_on", power=min(power, 1.0))
        for k, setting in enumerate(settings):
            builder.add_segment([base + pieces[k] * axis, base + pieces[k + 1] * axis], axes=axis,
                                kind="cure", feed=setting.feed, tool=tool_number,
                                flow=setting.energy_per_mm)
        builder.event("light_off")
        builder.add_segment([base + top * axis], axes=axis, kind="travel", feed=travel_feed,
                            tool=tool_number)
    return builder
