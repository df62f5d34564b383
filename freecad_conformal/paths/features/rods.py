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
mm of rod is inversely proportional to the speed). METHODS gives one measured point (small
tool, ∅ ~1.2 mm at 0.75 mm/s) and the working curve's shape, not a point-curing model; the
line-width model cannot be used as is (with a 0.3 mm spot it never reaches 1.2 mm). So
`PointCuring` keeps the working curve's form, d = B·sqrt(Cd / (2·Dp)) with
Cd = Dp·ln(E/Ec), E ∝ 1/v, calibrated on the reference point with E_ref/Ec = e^q (q, the
reference cure depth in penetration depths, defaults to 4: a placeholder for a DOE).
A diameter profile along the rod becomes one feed per piece.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from freecad_conformal.errors import PlanError
from freecad_conformal.process.curing import (
    cure_depth, depth_for_line_width, exposure_for_depth, line_width)
from freecad_conformal.process.tools import Tool
from freecad_conformal.toolpath import ToolpathBuilder

#: Heights (mm) between envelope samples in the collision test: 0.05 mm is far below any
#: rod diameter (>= 0.2 mm), so a contact cannot slip between two samples.
ENVELOPE_STEP = 0.05

#: METHODS section 1: rods of ∅ ~1.2 mm with the small tool at 0.75 mm/s (45 mm/min).
REFERENCE_DIAMETER = 1.2
REFERENCE_FEED = 45.0
#: ln(E_ref / Ec) at the reference point (placeholder, see the module docstring).
REFERENCE_DEPTH_RATIO = 4.0

#: Clearance (mm) the tool retracts along the rod axis before moving to the next rod.
RETRACT = 2.0


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
    limit = int(math.floor(max_tilt / theta + 1e-9))
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
                     np.asarray(center, dtype=float) + radius * axes, axes, np.array(ring_of))


def cylinder_layout(origin, axis, radius: float, spacing: float, diameter: float, length: float,
                    start: float, stop: float) -> RodLayout:
    """Rings d apart along the cylinder axis from `start` to `stop` (mm), floor(2πR/d) rods each."""
    if not (radius > 0 and spacing > 0 and diameter > 0 and length > 0):
        raise PlanError(f"rods: R {radius!r}, d {spacing!r}, a {diameter!r}, l {length!r} must be > 0")
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    u, v = _frame(axis)
    n = int(math.floor(2 * math.pi * radius / spacing))
    beta = 2 * math.pi / n
    positions = np.arange(start, stop + 1e-9, spacing)
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
                     np.array(normals), np.array(ring_of))


def _segment_distance(points: np.ndarray, start: np.ndarray, end: np.ndarray) -> np.ndarray:
    chord = end - start
    t = np.clip((points - start) @ chord / max(float(chord @ chord), 1e-300), 0.0, 1.0)
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


@dataclass(frozen=True)
class PointCuring:
    """Rod diameter versus speed for point curing, in normalised units (Dp = Ec = 1)."""

    reference_diameter: float = REFERENCE_DIAMETER
    reference_feed: float = REFERENCE_FEED
    depth_ratio: float = REFERENCE_DEPTH_RATIO

    @property
    def _spot(self) -> float:
        return self.reference_diameter * math.sqrt(2.0 / self.depth_ratio)

    def diameter(self, feed: float) -> float:
        """Rod diameter (mm) at `feed` mm/min (0 when nothing cures)."""
        exposure = math.exp(self.depth_ratio) * self.reference_feed / feed
        return line_width(cure_depth(exposure, 1.0, 1.0), self._spot, 1.0)

    def feed_for_diameter(self, diameter: float) -> float:
        """Feed (mm/min) that cures a rod `diameter` mm wide."""
        if not diameter > 0:
            raise PlanError(f"rods: diameter must be > 0 mm, got {diameter!r}")
        exposure = exposure_for_depth(depth_for_line_width(diameter, self._spot, 1.0), 1.0, 1.0)
        return self.reference_feed * math.exp(self.depth_ratio) / exposure


def rod_feeds(curing: PointCuring, diameters, max_feed: float | None = None) -> np.ndarray:
    """Point-curing feed (mm/min) for each rod diameter (mm); PlanError above `max_feed`."""
    feeds = np.array([curing.feed_for_diameter(float(a)) for a in np.atleast_1d(diameters)])
    if max_feed is not None and np.any(feeds > max_feed):
        k = int(np.argmax(feeds))
        raise PlanError(f"rods: a diameter of {np.atleast_1d(diameters)[k]:g} mm needs "
                        f"{feeds[k]:.4g} mm/min, faster than {max_feed:g} mm/min: too thin for "
                        "this tool")
    return feeds


def rods_toolpath(layout: RodLayout, tool: Tool, curing: PointCuring, tool_number: int = 1,
                  profile: list[float] | None = None, travel_feed: float = 600.0,
                  power: float = 1.0, builder: ToolpathBuilder | None = None) -> ToolpathBuilder:
    """Steps 9–15: for each rod, travel to its base on the normal, light on, move along the
    normal for l (one piece per entry of the diameter `profile`, default constant a, each at
    its own feed), light off, retract."""
    builder = builder or ToolpathBuilder(part="rods", material="UV resin")
    diameters = np.asarray(profile if profile else [layout.diameter], dtype=float)
    feeds = rod_feeds(curing, diameters)
    pieces = np.linspace(0.0, layout.length, len(diameters) + 1)
    for base, axis in zip(layout.bases, layout.axes):
        above = base + RETRACT * axis
        builder.add_segment([above, base], axes=axis, kind="travel", feed=travel_feed, tool=tool_number)
        builder.event("light_on", power=power)
        for k, feed in enumerate(feeds):
            builder.add_segment([base + pieces[k] * axis, base + pieces[k + 1] * axis], axes=axis,
                                kind="cure", feed=float(feed), tool=tool_number)
        builder.event("light_off")
        builder.add_segment([base + (layout.length + RETRACT) * axis], axes=axis, kind="travel",
                            feed=travel_feed, tool=tool_number)
    return builder
