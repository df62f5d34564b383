"""Milling passes of a hybrid plan (METHODS section 6), from 2D regions to 3D tool poses.

A pass is a polyline of tool-tip points with one tool axis, and the volume its flat end
mill sweeps: the tool centre's path widened by the tool radius (a 2D region in a frame
normal to the axis), from the tip up along the axis for the flute length. The volume is
what the material check (`geometry/stock.py`) subtracts from the deposit.

- Side finishing (`contour_passes`): the tool centre runs round the *forbidden* region: the
  part's material beside the flutes (its sections over the flute length, projected along
  the axis) widened by the tool radius, joined with the material beside the holder widened
  by the holder's radius. The flank then touches every wall it can reach and never cuts
  into the part; what it cannot reach stays as stock (the material check measures it).
- Facing (`facing_passes`): zigzag rows a stepover apart over a 3-D layer's top plane,
  where the nominal layer stands above it, clipped where the tool body would meet the part.
- Drilling (`drill_passes`): a plunge along a hole's axis when the tool is the hole's
  diameter, else a helix down the hole wall (pitch at most a quarter of the tool diameter).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely
from shapely.geometry import LineString, MultiPolygon, Polygon

from freecad_conformal.errors import PlanError
from freecad_conformal.geometry.frames import LayerFrame
from freecad_conformal.geometry.stock import Prism
from freecad_conformal.layers.model import as_multipolygon

#: Buffers of arcs use this many segments per quarter circle: a 3 mm tool radius is then
#: followed within 3·(1 − cos(π/64)) ≈ 0.004 mm, well inside the finishing tolerance.
ARC_SEGMENTS = 32

#: The outer side of a pass's swept region (stock and air only) is drawn with this many
#: segments per quarter circle.
COARSE_ARC_SEGMENTS = 4

#: Swept regions are simplified to this (mm): far below the finishing tolerance, it drops
#: the collinear points that only cost the material check time.
SIMPLIFY_SWEEP = 1e-4

#: Helix points per turn when a smaller tool mills a hole round.
HELIX_POINTS = 64

#: A helix descends at most this fraction of the tool diameter per turn (a gentle ramp).
HELIX_PITCH_FRACTION = 0.25

#: Rings of the forbidden region shorter than this (mm) are specks from sections, not walls.
MIN_RING = 1e-3


@dataclass(frozen=True)
class MillTool:
    """A flat end mill as the passes use it (mm, mm/min, rpm); `number` is its T word.
    A tapered cutter (`taper_deg` > 0, a V-bit) has a cone from a flat of `tip_diameter`
    to `diameter`; a ball end mill's `corner_radius` is its radius; the shank stands `reach`
    out of the holder (0: the flute length)."""

    number: int
    id: str
    diameter: float
    flute_length: float
    holder_diameter: float
    holder_length: float
    feed: float
    plunge_feed: float
    rpm: float
    stepover: float
    taper_deg: float = 0.0
    tip_diameter: float = 0.0
    reach: float = 0.0
    corner_radius: float = 0.0

    @property
    def radius(self) -> float:
        return 0.5 * self.diameter

    @property
    def tapered(self) -> bool:
        return self.taper_deg > 0.0

    @property
    def ball(self) -> bool:
        """A ball end mill: its corner radius is its radius."""
        return self.corner_radius >= self.radius - 1e-9

    @property
    def flat(self) -> bool:
        """A flat end mill, the geometry contour, facing and drilling passes assume."""
        return not self.tapered and self.corner_radius == 0.0

    @property
    def stick_out(self) -> float:
        """Where the holder begins, from the tip (mm)."""
        return max(self.reach, self.flute_length)


@dataclass
class MillPass:
    """One milling pass: tip points (n, 3) at one tool axis; `operation` is contour, face
    or drill; `sweep` what it removes."""

    points: np.ndarray
    axis: np.ndarray
    operation: str
    tool: MillTool
    feed: float
    #: the volume the pass removes (the region the tool centre's path widened by its
    #: radius, from the tip up the flute length)
    sweep: Prism
    #: moves at each end that run through air, at travel speed (a pencil pass's run-up)
    lead: int = 0

    @property
    def length(self) -> float:
        return float(np.linalg.norm(np.diff(self.points, axis=0), axis=1).sum())


def forbidden_region(flutes: MultiPolygon, holder: MultiPolygon, tool: MillTool) -> MultiPolygon:
    """Where the tool centre must not go: the part beside the flutes widened by the tool
    radius, with the part beside the holder widened by the holder radius."""
    zones = [flutes.buffer(tool.radius, quad_segs=ARC_SEGMENTS)]
    if not holder.is_empty:
        zones.append(holder.buffer(0.5 * tool.holder_diameter, quad_segs=ARC_SEGMENTS))
    return as_multipolygon(shapely.union_all(zones))


def contour_passes(forbidden: MultiPolygon, near: MultiPolygon, frame: LayerFrame,
                   tip_height: float, tool: MillTool) -> list[MillPass]:
    """Closed passes round the rings of `forbidden` that come within reach of `near` (the
    deposit to be finished, frame coordinates), tip at `tip_height` along frame.n."""
    reach = near.buffer(tool.radius + 1e-6)
    passes = []
    for polygon in forbidden.geoms:
        for ring in [polygon.exterior, *polygon.interiors]:
            if ring.length < MIN_RING or not ring.intersects(reach):
                continue
            uv = np.asarray(ring.coords)
            passes.append(MillPass(frame.to_3d(uv, tip_height), frame.n.copy(), "contour", tool,
                                   tool.feed, Prism(frame, ring_sweep(ring, tool.radius), tip_height,
                                                    tool.flute_length)))
    return passes


def ring_sweep(ring, radius: float) -> MultiPolygon:
    """The region a tool of `radius` sweeps with its centre round the closed `ring`: the
    ring's polygon widened by the radius, less the polygon narrowed by it (the band within the
    radius of a closed curve, exactly).
    The outer side only meets stock and air, so it is drawn coarsely (fewer faces for the
    material check's Booleans)."""
    polygon = Polygon(ring.coords)
    outer = polygon.buffer(radius, quad_segs=COARSE_ARC_SEGMENTS)
    inner = polygon.buffer(-radius, quad_segs=ARC_SEGMENTS).simplify(SIMPLIFY_SWEEP)
    return as_multipolygon(outer.difference(inner))


def facing_passes(top: MultiPolygon, forbidden: MultiPolygon, frame: LayerFrame,
                  tip_height: float, tool: MillTool) -> list[MillPass]:
    """Zigzag rows over `top` (the material standing above the plane, frame coordinates)
    covering it to its edge, the tool centre kept out of `forbidden`."""
    if top.is_empty:
        return []
    cover = top.buffer(tool.radius * (1.0 - 1e-3), quad_segs=ARC_SEGMENTS)
    allowed = cover.difference(forbidden) if not forbidden.is_empty else cover
    if allowed.is_empty:
        return []
    x0, y0, x1, y1 = allowed.bounds
    step = min(tool.stepover, tool.diameter * 0.9)
    count = max(1, int(math.ceil((y1 - y0) / step)))
    rows = []
    for k in range(count + 1):
        y = min(y0 + k * step, y1)
        pieces = LineString([(x0 - 1.0, y), (x1 + 1.0, y)]).intersection(allowed)
        lines = [g for g in getattr(pieces, "geoms", [pieces]) if g.geom_type == "LineString" and not g.is_empty]
        for line in sorted(lines, key=lambda g: g.bounds[0]):
            coords = np.asarray(line.coords)
            rows.append(coords if k % 2 == 0 else coords[::-1])
    passes = []
    for uv in rows:
        sweep = LineString(uv).buffer(tool.radius, quad_segs=ARC_SEGMENTS) if len(uv) > 1 else None
        if sweep is None or sweep.is_empty:
            continue
        passes.append(MillPass(frame.to_3d(uv, tip_height), frame.n.copy(), "face", tool,
                               tool.feed, Prism(frame, as_multipolygon(sweep), tip_height,
                                                tool.flute_length)))
    return passes


def drill_passes(entry: np.ndarray, inward: np.ndarray, radius: float, depth: float,
                 tool: MillTool) -> list[MillPass]:
    """Cut a round hole of `radius` from `entry` (a point on its axis where the tool
    enters) `depth` mm along `inward`: a plunge with a tool of the hole's size, a helix
    with a smaller one. Raises PlanError when the tool is wider than the hole or its
    flutes shorter than the depth."""
    if tool.radius > radius + 1e-9:
        raise PlanError(f"mill tool {tool.id!r} ({tool.diameter:g} mm) is wider than a hole of "
                        f"{2 * radius:g} mm")
    if depth > tool.flute_length + 1e-9:
        raise PlanError(f"mill tool {tool.id!r} reaches {tool.flute_length:g} mm deep, the hole "
                        f"needs {depth:.3f} mm")
    axis = -np.asarray(inward, dtype=float) / np.linalg.norm(inward)
    frame = LayerFrame.for_direction(axis)
    top = float(np.asarray(entry) @ frame.n)
    centre = frame.to_2d(np.asarray(entry)[None])[0]
    offset = radius - tool.radius
    if offset < 1e-6:
        uv = np.array([centre, centre])
        heights = np.array([top, top - depth])
    else:
        pitch = HELIX_PITCH_FRACTION * tool.diameter
        turns = max(1.0, depth / pitch)
        t = np.linspace(0.0, turns + 1.0, int((turns + 1.0) * HELIX_POINTS) + 1)
        angle = 2.0 * math.pi * t
        uv = centre + offset * np.column_stack((np.cos(angle), np.sin(angle)))
        heights = top - np.minimum(t / turns, 1.0) * depth     # a last full turn at the bottom
    points = (np.outer(uv[:, 0], frame.u) + np.outer(uv[:, 1], frame.v)
              + np.outer(heights, frame.n))
    disc = shapely.Point(*centre).buffer(radius, quad_segs=ARC_SEGMENTS)
    sweep = Prism(frame, MultiPolygon([disc]), top - depth, depth)
    return [MillPass(points, frame.n.copy(), "drill", tool, tool.plunge_feed if offset < 1e-6
                     else tool.feed, sweep)]
