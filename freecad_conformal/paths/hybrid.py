"""The order of a hybrid plan: when to deposit, when to mill, and which passes (METHODS 6).

Deposition goes on layer after layer and stops for milling only when it must:
- a 3-D layer was deposited as a nominal layer (uniform `d_max`) and its top must be faced
  to the layer's real top plane before anything is laid on it;
- the next layer reaches out beyond this one (the wall turns outward: a face with no
  neighbour below): the walls built so far would then sit under material the tool cannot
  reach past;
- the next layer would stand higher above the first unfinished layer than the shortest
  tool of the session reaches (the finishing cutter's flutes, or a drill's for a hole
  along the build direction, drilled layer by layer as METHODS' nozzle example);
- the sub-part is finished.
Milling as late as these rules allow gives the fewest switches a plan with them can have
(each rule bounds how far deposition may run, and taking each run to its bound is the
greedy cover, which is optimal for intervals). A naive plan switches after every layer.

Within a session: the side walls of each run of layers with one section (a prismatic
stretch) are finished by one contour pass with the tip at the run's bottom; passes see
only what is built (earlier sub-parts, and this sub-part up to the session's top), so a
branch built later does not hide the wall beneath it. Holes along the build direction
that were filled while depositing are cut through the session's layers; holes across it
are cut at the end, from their open ends, along their axes.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np
import shapely
from shapely.geometry import MultiPolygon

from freecad_conformal.errors import PlanError
from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry.face_normals import plane_normal
from freecad_conformal.geometry.frames import LayerFrame
from freecad_conformal.geometry.holes import Hole
from freecad_conformal.geometry.sections import PlanarSlicer
from freecad_conformal.geometry.stock import Prism
from freecad_conformal.layers.model import Layer, as_multipolygon
from freecad_conformal.paths.map3d import Path3D
from freecad_conformal.paths.milling import (MillPass, MillTool, contour_passes, drill_passes,
                                             facing_passes, forbidden_region)

#: The next layer "reaches out" when it extends beyond this one by more than this (mm):
#: sections of one prism agree to far less, and a real outward step is wider.
GROWTH_TOLERANCE = 1e-3

#: Two consecutive layers share one contour pass when their regions differ by less than
#: this fraction of the area (the same prismatic stretch).
SAME_SECTION = 1e-6

#: Sections of what is built are sampled this often (mm) over a pass's reach along its
#: axis (at least every layer); a feature thinner than this between samples is missed.
SHADOW_STEP = 0.5

#: A drill goes this much (mm) past the session's bottom so consecutive cuts of one hole
#: overlap.
DRILL_OVERLAP = 0.05

#: A hole axis leaning more than this from the build direction is "across" it (filled
#: while depositing and cut at the end); within it, "along" (cut layer by layer).
ALONG_LIMIT = math.radians(1.0)


@dataclass
class Session:
    """One switch to milling: after depositing layers `first..last` of `subpart`."""

    subpart: int
    first: int
    last: int
    reason: str
    passes: list[MillPass] = field(default_factory=list)


@dataclass
class Step:
    """Deposit one layer (`paths`, tip points, with `nominal` when it is a 3-D layer built
    uniformly thick) or mill one session."""

    kind: str                         # "deposit" or "mill"
    paths: list[Path3D] = field(default_factory=list)
    session: Session | None = None


@dataclass
class HybridSequence:
    steps: list[Step]
    deposits: list[Prism]
    sessions: list[Session]
    layers_deposited: int
    notes: list[str] = field(default_factory=list)

    @property
    def switches(self) -> int:
        """Deposition ↔ milling switches (the last session ends the program)."""
        return max(0, 2 * len(self.sessions) - 1)

    @property
    def naive_switches(self) -> int:
        """Switches of a plan that mills after every layer."""
        return max(0, 2 * self.layers_deposited - 1)


def nominal_paths(paths: list[Path3D], lower_point: np.ndarray, lower_normal: np.ndarray,
                  d_max: float) -> list[Path3D]:
    """A 3-D layer's paths moved onto the nominal top: `d_max` above the lower plane along
    its normal, the tool along that normal (the layer is deposited uniformly thick)."""
    n = np.asarray(lower_normal, dtype=float)
    level = float(np.asarray(lower_point) @ n) + d_max
    out = []
    for path in paths:
        points = path.points + np.outer(level - path.points @ n, n)
        out.append(Path3D(points=points, axis=n.copy(), role=path.role, subpart=path.subpart,
                          layer=path.layer, thickness=d_max, closed=path.closed,
                          width=path.width))
    return out


def layer_bottom(layer: Layer) -> float:
    """Height along the layer's top normal of its slab's lowest point."""
    return float(layer.top_point @ layer.top_normal) - layer.thickness_max


def deposit_prism(layer: Layer, lower_point: np.ndarray | None, lower_normal: np.ndarray | None,
                  stock: float, d_max: float) -> Prism:
    """What one layer deposits: its region widened by the stock allowance, as a prism on
    the layer's lower plane (a 3-D layer: `d_max` thick along the lower normal)."""
    region = layer.region.buffer(stock, quad_segs=8) if stock > 0 else layer.region
    if not layer.tilted or lower_point is None:
        top = float(layer.top_point @ layer.top_normal)
        frame = LayerFrame.for_direction(layer.top_normal)
        moved = _moved(region, layer.frame, layer.section_height, frame)
        return Prism(frame, moved, top - layer.thickness_max, layer.thickness_max)
    frame = LayerFrame.for_direction(lower_normal)
    moved = _moved(region, layer.frame, layer.section_height, frame)
    return Prism(frame, moved, float(np.asarray(lower_point) @ frame.n), d_max)


def _moved(region, source: LayerFrame, height: float, target: LayerFrame) -> MultiPolygon:
    """`region` (source frame at `height`) in `target`'s coordinates, projected along its n."""
    if np.allclose(source.u, target.u) and np.allclose(source.v, target.v):
        return as_multipolygon(region)

    def move(uv: np.ndarray) -> np.ndarray:
        return target.to_2d(source.to_3d(uv, height))

    return as_multipolygon(shapely.transform(region, move).buffer(0))


class Shadows:
    """Sections of what is built, projected along one axis over a height range (`current`,
    the sub-part being built, only below `current_top`; None when all is built)."""

    def __init__(self, built: Sequence, current, current_top: float, normal: np.ndarray) -> None:
        self.normal = np.asarray(normal, dtype=float)
        self.frame = LayerFrame.for_direction(self.normal)
        self._slicers = [PlanarSlicer(shape, self.normal) for shape in built]
        self._current = PlanarSlicer(current, self.normal) if current is not None else None
        self._top = current_top
        # the silhouette of a part along the axis has its corners at the heights of its
        # vertices: sections there make the projected outline exact for planar faces
        # (between samples a 45° block's corner was missed by 0.1 mm, and cut)
        self._corners = np.unique(np.round(np.concatenate(
            [np.array([tuple(v.Point) for v in shape.Vertexes]).reshape(-1, 3) @ self.normal
             for shape in [*built, *([current] if current is not None else [])]] or
            [np.zeros(0)]), 9))

    def over(self, low: float, high: float, step: float) -> MultiPolygon:
        """What is built between heights `low` and `high` (this sub-part only below its
        current top), seen along the axis."""
        if high <= low:
            return MultiPolygon()
        count = max(2, int(math.ceil((high - low) / step)) + 1)
        corners = self._corners[(self._corners > low + 1e-4) & (self._corners < high - 1e-4)]
        heights = sorted(set(np.linspace(low + 1e-4, high - 1e-4, count).tolist())
                         | set((corners - 1e-4).tolist()) | set((corners + 1e-4).tolist()))
        heights = [h for h in heights if low < h < high]
        pieces = []
        for slicer in self._slicers:
            pieces += _refined(slicer, heights)
        mine = [h for h in heights if h <= self._top - 1e-4]
        if low < self._top - 1e-4 < high:
            mine.append(self._top - 1e-4)     # the last layer's section, just under the top
        if mine and self._current is not None:
            pieces += _refined(self._current, mine)
        return as_multipolygon(shapely.union_all(pieces)) if pieces else MultiPolygon()


#: Between two sampled heights a curved wall can bulge past both sections (the bottle's
#: lip: contour passes cut 0.25 mm into it): where the section halfway sticks out of the
#: two by more than this (mm; what a pass could cut, well under the 0.05 mm tolerance),
#: it is kept and both halves are looked at again ...
BULGE_DEPTH = 0.02

#: ... down to intervals this short (mm).
SHORTEST_STEP = 0.05


def _refined(slicer: PlanarSlicer, heights: list[float]) -> list:
    """Sections' polygons at `heights`, with sections added between neighbours where the
    one halfway sticks out of the two (`BULGE_DEPTH`)."""
    heights = sorted(heights)
    found = {h: s for h, s in zip(heights, slicer.sections(heights))}
    polygons = {h: (as_multipolygon(s.polygons()) if not s.is_empty else MultiPolygon())
                for h, s in found.items()}
    gaps = [(a, b) for a, b in zip(heights, heights[1:]) if b - a > 2 * SHORTEST_STEP]
    while gaps:
        middles = [0.5 * (a + b) for a, b in gaps]
        for h, section in zip(middles, slicer.sections(middles)):
            polygons[h] = (as_multipolygon(section.polygons()) if not section.is_empty
                           else MultiPolygon())
        next_gaps = []
        for (a, b), h in zip(gaps, middles):
            outside = polygons[h].difference(shapely.union(polygons[a], polygons[b]))
            if not outside.is_empty and not outside.buffer(-0.5 * BULGE_DEPTH).is_empty:
                next_gaps += [(lo, hi) for lo, hi in ((a, h), (h, b))
                              if hi - lo > 2 * SHORTEST_STEP]
            else:
                del polygons[h]          # inside its neighbours: adds nothing to the shadow
        gaps = next_gaps
    return [p for p in polygons.values() if not p.is_empty]


def _forbidden(shadows: Shadows, tip: float, tool: MillTool, step: float) -> MultiPolygon:
    flutes = shadows.over(tip, tip + tool.flute_length, step)
    holder = shadows.over(tip + tool.flute_length,
                          tip + tool.flute_length + tool.holder_length, max(step, 1.0))
    return forbidden_region(flutes, holder, tool)


def _runs(layers: Sequence[Layer]) -> list[list[Layer]]:
    """Consecutive layers with one normal and one section, grouped."""
    runs: list[list[Layer]] = []
    for layer in layers:
        last = runs[-1][-1] if runs else None
        if (last is not None and not layer.tilted and not last.tilted
                and np.allclose(last.top_normal, layer.top_normal)
                and last.region.symmetric_difference(layer.region).area
                <= SAME_SECTION * max(layer.area, 1.0)):
            runs[-1].append(layer)
        else:
            runs.append([layer])
    return runs


def grows_out(lower: Layer, upper: Layer) -> bool:
    """True when `upper` reaches beyond `lower` (planar layers of one normal)."""
    if upper.tilted or lower.tilted or not np.allclose(lower.top_normal, upper.top_normal):
        return False
    beyond = upper.region.difference(lower.region.buffer(GROWTH_TOLERANCE))
    return not beyond.is_empty and beyond.area > GROWTH_TOLERANCE ** 2


def finishing_passes(layers: Sequence[Layer], shadows_for, stock: float, tool: MillTool,
                     step: float) -> list[MillPass]:
    """Contour passes finishing the walls of `layers`, top run first (so the tool never
    passes under material it has yet to cut); `shadows_for(normal)` gives the Shadows."""
    passes: list[MillPass] = []
    for run in reversed(_runs(layers)):
        normal = run[0].top_normal
        shadows = shadows_for(normal)
        tip = min(layer_bottom(layer) for layer in run)
        top = max(float(layer.top_point @ normal) for layer in run)
        near = as_multipolygon(shapely.union_all(
            [_moved(layer.region.buffer(stock, quad_segs=8), layer.frame, layer.section_height,
                    shadows.frame) for layer in run]))
        height = top - tip
        for k in range(max(1, int(math.ceil(height / tool.flute_length - 1e-9)))):
            level = tip + k * tool.flute_length
            forbidden = _forbidden(shadows, level, tool, step)
            passes += contour_passes(forbidden, near, shadows.frame, level, tool)
    return passes


def facing(layer: Layer, lower_point: np.ndarray, lower_normal: np.ndarray, d_max: float,
           stock: float, shadows: Shadows, tool: MillTool, step: float) -> list[MillPass]:
    """Face a nominal 3-D layer down to its top plane."""
    top = float(layer.top_point @ layer.top_normal)
    deposit = deposit_prism(layer, lower_point, lower_normal, stock, d_max)
    footprint = _moved(deposit.region, deposit.frame, deposit.bottom + d_max, shadows.frame)
    forbidden = _forbidden(shadows, top, tool, step)
    return facing_passes(footprint, forbidden, shadows.frame, top, tool)


def face_to(prisms: Sequence[Prism], point: np.ndarray, normal: np.ndarray, shadows: Shadows,
            tool: MillTool, step: float) -> list[MillPass]:
    """Face what `prisms` deposited down to the plane (`point`, `normal`): a run of 3-D
    layers deposited as planar layers (paths/hybrid_groups.py)."""
    top = float(np.asarray(point) @ np.asarray(normal))
    footprint = as_multipolygon(shapely.union_all(
        [_moved(p.region, p.frame, p.bottom + p.height, shadows.frame) for p in prisms]))
    forbidden = _forbidden(shadows, top, tool, step)
    return facing_passes(footprint, forbidden, shadows.frame, top, tool)


def drill_tool(hole: Hole, tools: Sequence[MillTool]) -> MillTool | None:
    """The widest tool that fits the hole (None when none does)."""
    fitting = [t for t in tools if t.radius <= hole.radius + 1e-9 and t.flat]
    return max(fitting, key=lambda t: t.diameter) if fitting else None


def along(hole: Hole, normal: np.ndarray) -> bool:
    return not hole.across(np.asarray(normal, dtype=float), ALONG_LIMIT)


def session_drills(holes: Sequence[Hole], normal: np.ndarray, bottom: float, top: float,
                   tools: Sequence[MillTool]) -> list[MillPass]:
    """Cut the filled holes along `normal` through the layers between `bottom` and `top`."""
    passes = []
    n = np.asarray(normal, dtype=float)
    for hole in holes:
        if not along(hole, n):
            continue
        ends = sorted(float(hole.end(w) @ n) for w in ("low", "high"))
        low, high = max(ends[0], bottom - DRILL_OVERLAP), min(ends[1], top)
        if high - low <= DRILL_OVERLAP:
            continue
        tool = drill_tool(hole, tools)
        if tool is None:
            raise PlanError(f"no mill tool fits the {hole.diameter:g} mm hole; give one at most "
                            "that wide with --mill-tool")
        entry = hole.point + (high - float(hole.point @ n)) * n
        passes += drill_passes(entry, -n, hole.radius, high - low, tool)
    return passes


def final_drills(holes: Sequence[Hole], normals: Sequence[np.ndarray],
                 tools: Sequence[MillTool], notes: list[str]) -> list[MillPass]:
    """Cut the holes across every build direction, from their open ends."""
    passes = []
    for hole in holes:
        if any(along(hole, n) for n in normals):
            continue
        tool = drill_tool(hole, tools)
        if tool is None:
            raise PlanError(f"no mill tool fits the {hole.diameter:g} mm hole; give one at most "
                            "that wide with --mill-tool")
        ends = [(w, hole.direction if w == "low" else -hole.direction) for w in hole.open_ends]
        if not ends:
            notes.append(f"the {hole.diameter:g} mm hole across the build opens at neither end: "
                         "left filled")
            continue
        share = hole.length / 2.0 + DRILL_OVERLAP if hole.through else hole.length
        if share > tool.flute_length:
            notes.append(f"the {hole.diameter:g} mm hole across the build is {hole.length:.1f} mm "
                         f"long; {tool.id} reaches {tool.flute_length:g} mm from "
                         f"{'each end' if hole.through else 'its open end'}: left uncut")
            continue
        for which, inward in ends:
            passes += drill_passes(hole.end(which), inward, hole.radius, share, tool)
    return passes


def finishing_axes(shapes: Sequence, directions: Sequence[np.ndarray], root: np.ndarray) -> list[np.ndarray]:
    """Tool axes for the last finishing passes: the build directions, and for each planar
    face parallel to none of them the direction in its plane nearest the root direction
    (a flat end mill's flank along that axis lies on the face: "3+2" finishing)."""
    axes = [np.asarray(d, dtype=float) / np.linalg.norm(d) for d in directions]
    up = np.asarray(root, dtype=float) / np.linalg.norm(root)
    for shape in shapes:
        for face in shape.Faces:
            m = plane_normal(face)        # B-spline planes too (lofts, exporters)
            if m is None:
                continue
            if any(abs(float(m @ a)) < PARALLEL_FACE for a in axes):
                continue
            along_face = up - float(up @ m) * m
            if np.linalg.norm(along_face) < 1e-9:
                continue                  # a face square to the root: a top, faced or built flat
            along_face /= np.linalg.norm(along_face)
            # and across it: along the face's rise the rest of the part often stands in
            # the way (a branch's underside over its block), across it seldom
            for axis in (along_face, np.cross(m, along_face)):
                if not any(float(axis @ a) > 1.0 - 1e-9 for a in axes):
                    axes.append(axis)
    return axes


#: A planar face is finished by a pass along an axis when the axis lies in its plane to
#: this (the cosine between the face normal and the axis).
PARALLEL_FACE = 1e-6


def final_finishing(shapes: Sequence, axes: Sequence[np.ndarray], tool: MillTool,
                    step: float) -> list[MillPass]:
    """Contour passes along each axis over the whole built part, level by level a flute
    length apart, round every ring that touches the part's walls."""
    from freecad_conformal.geometry.sections import extent_along

    App, Part = import_freecad()
    compound = Part.makeCompound(list(shapes))
    passes: list[MillPass] = []
    for axis in axes:
        shadows = Shadows(shapes, None, -math.inf, axis)
        low, high = extent_along(compound, shadows.normal)
        level = low
        while level < high - 1e-6:
            flutes = shadows.over(level, min(level + tool.flute_length, high), step)
            holder = shadows.over(level + tool.flute_length,
                                  level + tool.flute_length + tool.holder_length, max(step, 1.0))
            forbidden = forbidden_region(flutes, holder, tool)
            passes += contour_passes(forbidden, flutes.buffer(STOCK_REACH), shadows.frame,
                                     level, tool)
            level += FINAL_LEVEL_FRACTION * tool.flute_length
    return passes


#: Final passes go round rings within this (mm) of the part's walls plus the tool radius.
STOCK_REACH = 1.0

#: Last passes along an axis start every this fraction of the flute length: a wall the
#: rest of the part hides from one tip level is often clear from a nearby one.
FINAL_LEVEL_FRACTION = 0.25
