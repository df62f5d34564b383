"""Support under what a plan leaves overhanging, printed in the sub-part's own planar layers.

A plan is chosen to leave no overhang; where none is found that does (CrankArm's 1170 mm²,
a closed cavity's ceiling), `plan --support` prints support under what is left, as a planar
slicer does with supports on (PrusaSlicer's defaults: rectilinear lines with 2.5 mm between them,
three solid interface layers under the overhang, one layer of contact gap above and
below, half a bead clear of the part sideways).

Per layer, the overhang is what lies beyond the layer below by more than the allowed angle
(and at least half a bead: the perimeter carries that much). Going down the stack, each
overhang becomes a column one contact layer below it; a column stops where it meets the
part (a layer holding it: it stands on the part there, one contact layer above it). A
slope a little past the angle overhangs by a sliver on each layer, a comb of them one step
apart: the columns are closed over `CLOSING_RADIUS` into one band before the part and its
clearance are taken out.
A column standing on the part starts with `bottom_interface_layers` solid layers (as many
as on top by default, as PrusaSlicer's); one on the platform starts sparse.
What a bridge spans from wall to wall (`bridged`: the fill's rows with both ends on the
layer below) gets no columns, as PrusaSlicer's default "Don't support bridges";
`SupportSettings.bridges` supports it too.
Columns still open at the first layer stand on the platform where the sub-part does; on a
sub-part resting on its parent they would stand on whatever lies below its base, which
its own layers do not know, so only what stands on the sub-part itself is kept and the
rest counted (`StackSupport.dropped_area`).
Only stacks of planar layers in one direction get support: 3-D layers tilt the nozzle, and
a column along one tilt meets the next layer askew.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np
import shapely
from shapely.geometry import MultiPolygon

from freecad_conformal.geometry.overhang import DEFAULT_OVERHANG_ANGLE
from freecad_conformal.layers.model import Layer, as_multipolygon
from freecad_conformal.paths.bead import bead_spacing
from freecad_conformal.paths.fill2d import Path2D, zigzag
from freecad_conformal.paths.map3d import SAME_REGION, bridge_wide, region_in
from freecad_conformal.paths.scan import anchored_cover, bridge_angle, polygons_of

#: Roles of the paths support is printed in.
SUPPORT_ROLES = ("support", "support_interface")
#: Layers of gap between a column and the overhang it carries, and the part it stands on:
#: PrusaSlicer's contact distance (0.2 mm) at its 0.2 mm layers, so support breaks away.
CONTACT_LAYERS = 1
#: Sideways clearance between support and the part, in bead widths (PrusaSlicer's 50 %).
XY_GAP_BEADS = 0.5
#: Support lines run along the layer frame's u axis, interface lines across them.
SUPPORT_ANGLE, INTERFACE_ANGLE = 0.0, 0.5 * math.pi
#: A layer's step past the one below beyond the allowed reach by more than this (mm) is
#: overhang: a wall at exactly the angle steps by the reach, and rounding leaves slivers a
#: billionth of a millimetre wide that the closing would join into a band under it.
SLOPE_SLACK = 0.01
#: Columns closer than twice this (mm) are joined: a comb of slivers one layer's step
#: apart (0.2-0.4 mm on slopes a little past 45 degrees) becomes one band. PrusaSlicer's
#: default closing radius is 2 mm; at 2 mm CrankArm's support grew from 1.0 to 2.5 cm³
#: (holes between its columns filled) and took 7 s to close.
CLOSING_RADIUS = 0.5
#: Segments per quarter circle of the closing's round corners: support needs no finer.
CLOSING_SEGMENTS = 4
#: Normals of two planar layers this close (the cosine) are one direction.
SAME_NORMAL = 1.0 - 1e-9


@dataclass(frozen=True)
class SupportSettings:
    """Whether support is printed, the gap between its lines (mm) and its solid interface
    layers."""

    enabled: bool = False
    #: gap between support lines, as PrusaSlicer's "pattern spacing": the lines lie one
    #: bead spacing farther apart than this (0: solid)
    spacing: float = 2.5
    interface_layers: int = 3
    #: solid layers at the foot of a column standing on the part; -1: `interface_layers`
    bottom_interface_layers: int = -1
    #: also under what a bridge spans (PrusaSlicer's "Don't support bridges" is on)
    bridges: bool = False


@dataclass
class StackSupport:
    """Per layer of a stack, its sparse support and solid interface areas (layer frame), and
    the overhang area (mm²) whose columns were dropped: they would stand on nothing known."""

    base: list[MultiPolygon]
    interface: list[MultiPolygon]
    dropped_area: float = 0.0
    #: overhang (mm², summed over layers) left to bridges laid from wall to wall (`bridged`)
    bridged_area: float = 0.0

    @property
    def empty(self) -> bool:
        return all(a.is_empty for a in self.base) and all(a.is_empty for a in self.interface)


def supportable(layers: Sequence[Layer]) -> bool:
    """Whether the stack's layers are planar and in one direction (see the module)."""
    if not layers or any(layer.tilted for layer in layers):
        return False
    first = np.asarray(layers[0].top_normal, dtype=float)
    return all(float(np.asarray(layer.top_normal, dtype=float) @ first) > SAME_NORMAL
               for layer in layers)


def overhangs(layers: Sequence[Layer], bead_width: float,
              angle: float = DEFAULT_OVERHANG_ANGLE) -> list[MultiPolygon]:
    """Per layer, what it holds beyond the layer below by more than `angle` allows (and
    half a bead); none on the first layer (it rests on the base)."""
    found = [MultiPolygon()]
    for below, layer in zip(layers, layers[1:]):
        under = region_in(layer, below)
        if layer.region.is_empty or shapely.equals_exact(layer.region, under, SAME_REGION):
            found.append(MultiPolygon())
            continue
        reach = max(layer.thickness * math.tan(angle), 0.5 * bead_width) + SLOPE_SLACK
        found.append(as_multipolygon(layer.region.difference(under.buffer(reach))))
    return found


#: A bridge row's end within this many bead widths of the layer below rests on it: an end
#: on the piece's edge along a wall lies on it (the layer below reaches the wall), one on a
#: free edge a bead or more away.
ANCHOR_BEADS = 0.5


def bridged(layer: Layer, under: MultiPolygon, bead_width: float) -> MultiPolygon:
    """What of `layer` over nothing (beyond `under`, the layer below in its frame) a bridge
    spans: in each piece wide enough to bridge (`map3d.bridge_wide`), the rows laid from anchor
    to anchor (`scan.bridge_angle`, as the fill lays them) whose ends both rest on `under`.
    PrusaSlicer leaves that unsupported by default ("Don't support bridges": its bridge
    detector's coverage); a cantilever's rows end over air, so it stays supported."""
    if under.is_empty:
        return MultiPolygon()
    reach = ANCHOR_BEADS * bead_width
    spans = []
    for piece in polygons_of(layer.region.difference(under)):
        if not bridge_wide(piece, bead_width):
            continue
        angle = bridge_angle(piece, bead_width, under, reach)
        cover = anchored_cover(piece, bead_width, angle, under, reach)
        if not cover.is_empty:
            spans.append(cover)
    return as_multipolygon(shapely.union_all(spans)) if spans else MultiPolygon()


def stack_support(layers: Sequence[Layer], settings: SupportSettings, bead_width: float,
                  on_platform: bool, angle: float = DEFAULT_OVERHANG_ANGLE) -> StackSupport:
    """The support areas of one stack (see the module); none where support is off or the
    stack is not `supportable`."""
    count = len(layers)
    if not settings.enabled or not supportable(layers):
        return StackSupport([MultiPolygon()] * count, [MultiPolygon()] * count)
    hang = overhangs(layers, bead_width, angle)
    bridged_area = 0.0
    if not settings.bridges:
        before = sum(h.area for h in hang)
        # On the grid: the bridge's rows and the overhang meet along the same edges, and
        # the difference left slivers 1e-13 mm² in area that became columns.
        hang = [h if h.is_empty else
                as_multipolygon(shapely.difference(
                    h, bridged(layers[i], region_in(layers[i], layers[i - 1]), bead_width),
                    grid_size=SUPPORT_GRID))
                for i, h in enumerate(hang)]
        bridged_area = before - sum(h.area for h in hang)
    if all(h.is_empty for h in hang):
        return StackSupport([MultiPolygon()] * count, [MultiPolygon()] * count, 0.0, bridged_area)
    gap = XY_GAP_BEADS * bead_width
    base, interface = [MultiPolygon()] * count, [MultiPolygon()] * count
    # Per layer, the columns passing it, closed: what a layer `interface_layers` above
    # holds too is sparse support, the rest the solid top of its column.
    passing = [MultiPolygon()] * count
    pending, closed = MultiPolygon(), MultiPolygon()
    for i in reversed(range(count)):
        layer = layers[i]
        top = i + 1 + CONTACT_LAYERS          # the overhang a column's top layer here carries
        changed = top < count and not hang[top].is_empty
        if changed:
            pending = as_multipolygon(pending.union(region_in(layer, layers[top], hang[top])))
        if pending.is_empty:
            continue
        if pending.intersects(layer.region):
            pending = as_multipolygon(pending.difference(_near(layer.region, pending, 0.0)))
            changed = True              # columns landed
        if changed:     # the columns as they were a layer up, closed once (most layers)
            closed = pending.buffer(CLOSING_RADIUS, quad_segs=CLOSING_SEGMENTS).buffer(
                -CLOSING_RADIUS, quad_segs=CLOSING_SEGMENTS)
        passing[i] = as_multipolygon(closed.difference(_near(layer.region, closed, 0.0)))
        area = passing[i].difference(_near(layer.region, passing[i], gap).buffer(gap))
        if i > 0 and CONTACT_LAYERS:        # a column stands a contact layer above the part
            area = area.difference(_near(region_in(layer, layers[i - 1]), area, 0.0))
        above = i + settings.interface_layers
        continuing = passing[above] if above < count else MultiPolygon()
        if shapely.equals_exact(passing[i], continuing, SAME_REGION):
            base[i] = as_multipolygon(area)     # the column goes on up: no top here (most)
            continue
        base[i] = as_multipolygon(shapely.intersection(area, continuing, grid_size=SUPPORT_GRID))
        interface[i] = as_multipolygon(shapely.difference(area, continuing,
                                                          grid_size=SUPPORT_GRID))
    _bottom_interfaces(layers, base, interface, settings)
    if on_platform or pending.is_empty:
        return StackSupport(base, interface, 0.0, bridged_area)
    # Columns open at the base of a sub-part resting on its parent stand on nothing known:
    # going up, only what stands on the part (or on a column that does) is kept.
    grounded = MultiPolygon()
    for i in range(count):
        if passing[i].is_empty:
            grounded = MultiPolygon()
            continue
        under = region_in(layers[i], layers[i - 1]) if i else MultiPolygon()
        grounded = as_multipolygon(passing[i].intersection(grounded.union(under)))
        base[i] = as_multipolygon(base[i].intersection(grounded))
        interface[i] = as_multipolygon(interface[i].intersection(grounded))
    return StackSupport(base, interface, float(pending.area), bridged_area)


def _bottom_interfaces(layers: Sequence[Layer], base: list, interface: list,
                       settings: SupportSettings) -> None:
    """Turn the foot of each column standing on the part solid, in place: its part in the
    `bottom_interface_layers` above the contact gap over the part (PrusaSlicer's bottom
    interface; a column on the platform has none)."""
    count = settings.bottom_interface_layers
    if count < 0:
        count = settings.interface_layers
    if count == 0:
        return
    for j, column in enumerate(base):
        lowest = j - CONTACT_LAYERS - count
        if column.is_empty or lowest + count < 0:
            continue
        under = [as_multipolygon(_near(region_in(layers[j], layers[k]), column, 0.0))
                 for k in range(max(lowest, 0), j - CONTACT_LAYERS)]
        under = [u for u in under if not u.is_empty]
        if not under:
            continue
        # Polygons only: where the column only touches the part's outline the intersection
        # holds lines, which a union with polygons refuses (mixed dimensions).
        foot = as_multipolygon(shapely.intersection(column, shapely.union_all(under),
                                                    grid_size=SUPPORT_GRID))
        if foot.is_empty:
            continue
        interface[j] = as_multipolygon(shapely.union(interface[j], foot, grid_size=SUPPORT_GRID))
        base[j] = as_multipolygon(shapely.difference(column, foot, grid_size=SUPPORT_GRID))


#: Grid (mm) the split of a column into its sparse body and solid top is made on: the
#: column a few layers up is nearly the same polygon, and GEOS's unsnapped overlay of
#: nearly coincident edges took 5.7 s of CrankArm's plan (0.7 s on this grid).
SUPPORT_GRID = 1e-6
#: Slack (mm) around a support area's box within which the part's region is kept for a
#: Boolean with it: the rest cannot change the result.
NEAR_SLACK = 1e-3


def _near(region: MultiPolygon, area, margin: float):
    """`region` clipped to `area`'s box widened by `margin`: a CrankArm section holds
    thousands of vertices, its support a few dozen, and GEOS's differences with the whole
    section took 4.7 s of the plan."""
    if region.is_empty or area.is_empty:
        return region
    x0, y0, x1, y1 = area.bounds
    pad = margin + NEAR_SLACK
    return shapely.clip_by_rect(region, x0 - pad, y0 - pad, x1 + pad, y1 + pad)


def support_paths(base: MultiPolygon, interface: MultiPolygon, settings: SupportSettings,
                  bead_width: float, height: float, bead_model: str) -> list[Path2D]:
    """One layer's support: sparse lines with `settings.spacing` between them, solid
    interface lines."""
    solid = bead_spacing(bead_width, height, bead_model)
    paths = []
    if not base.is_empty:
        # The gap, not the pitch: PrusaSlicer's lines at its default 2.5 mm lie 2.5 mm plus
        # a line's spacing apart (2.91 mm at 0.45 x 0.2 mm), 14 % less support than 2.5.
        paths += zigzag(base, settings.spacing + solid, SUPPORT_ANGLE, bead_width, "support")
    if not interface.is_empty:
        paths += zigzag(interface, solid, INTERFACE_ANGLE, bead_width, "support_interface")
    return paths
