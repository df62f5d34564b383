"""Support under what a plan leaves overhanging, printed in the sub-part's own planar layers.

A plan is chosen to leave no overhang; where none is found that does (CrankArm's 1170 mm²,
a closed cavity's ceiling), `plan --support` prints support under what is left, as a planar
slicer does with supports on (PrusaSlicer's defaults: rectilinear lines 2.5 mm apart,
three solid interface layers under the overhang, one layer of contact gap above and
below, half a bead clear of the part sideways).

Per layer, the overhang is what lies beyond the layer below by more than the allowed angle
(and at least half a bead: the perimeter carries that much), opened by half a bead (the
step a wall within the angle makes on each layer is no overhang). Going down the stack,
each overhang becomes a column one contact layer below it; a column stops where it meets
the part (a layer holding it: it stands on the part there, one contact layer above it).
Columns still open at the first layer stand on the platform where the sub-part does; on a
sub-part resting on its parent they would stand on whatever lies below its base, which
its own layers do not know, so they are dropped and counted (`StackSupport.dropped_area`).
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
from freecad_conformal.paths.map3d import SAME_REGION, region_in

#: Roles of the paths support is printed in.
SUPPORT_ROLES = ("support", "support_interface")
#: Layers of gap between a column and the overhang it carries, and the part it stands on:
#: PrusaSlicer's contact distance (0.2 mm) at its 0.2 mm layers, so support breaks away.
CONTACT_LAYERS = 1
#: Sideways clearance between support and the part, in bead widths (PrusaSlicer's 50 %).
XY_GAP_BEADS = 0.5
#: Support lines run along the layer frame's u axis, interface lines across them.
SUPPORT_ANGLE, INTERFACE_ANGLE = 0.0, 0.5 * math.pi
#: Normals of two planar layers this close (the cosine) are one direction.
SAME_NORMAL = 1.0 - 1e-9


@dataclass(frozen=True)
class SupportSettings:
    """Whether support is printed, its line spacing (mm) and its solid interface layers."""

    enabled: bool = False
    spacing: float = 2.5
    interface_layers: int = 3


@dataclass
class StackSupport:
    """Per layer of a stack, its sparse support and solid interface areas (layer frame), and
    the overhang area (mm²) whose columns were dropped: they would stand on nothing known."""

    base: list[MultiPolygon]
    interface: list[MultiPolygon]
    dropped_area: float = 0.0

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
    half a bead), opened by half a bead; none on the first layer (it rests on the base)."""
    half = 0.5 * bead_width
    found = [MultiPolygon()]
    for below, layer in zip(layers, layers[1:]):
        under = region_in(layer, below)
        if layer.region.is_empty or shapely.equals_exact(layer.region, under, SAME_REGION):
            found.append(MultiPolygon())
            continue
        reach = max(layer.thickness * math.tan(angle), half)
        bare = layer.region.difference(under.buffer(reach))
        found.append(as_multipolygon(bare.buffer(-half).buffer(half).intersection(layer.region))
                     if not bare.is_empty else MultiPolygon())
    return found


def stack_support(layers: Sequence[Layer], settings: SupportSettings, bead_width: float,
                  on_platform: bool, angle: float = DEFAULT_OVERHANG_ANGLE) -> StackSupport:
    """The support areas of one stack (see the module); none where support is off or the
    stack is not `supportable`."""
    count = len(layers)
    none = StackSupport([MultiPolygon()] * count, [MultiPolygon()] * count)
    if not settings.enabled or not supportable(layers):
        return none
    hang = overhangs(layers, bead_width, angle)
    if all(h.is_empty for h in hang):
        return none
    gap = XY_GAP_BEADS * bead_width
    base, interface = [MultiPolygon()] * count, [MultiPolygon()] * count
    pending = MultiPolygon()
    for i in reversed(range(count)):
        layer = layers[i]
        top = i + 1 + CONTACT_LAYERS          # the overhang a column's top layer here carries
        if top < count and not hang[top].is_empty:
            pending = as_multipolygon(pending.union(region_in(layer, layers[top], hang[top])))
        if pending.is_empty:
            continue
        pending = as_multipolygon(pending.difference(layer.region))     # columns landed
        area = pending.difference(layer.region.buffer(gap))
        if i > 0 and CONTACT_LAYERS:        # a column stands a contact layer above the part
            area = area.difference(region_in(layer, layers[i - 1]))
        near = [region_in(layer, layers[j], hang[j])
                for j in range(top, min(top + settings.interface_layers, count))
                if not hang[j].is_empty]
        carried = as_multipolygon(shapely.union_all(near)) if near else MultiPolygon()
        interface[i] = as_multipolygon(area.intersection(carried))
        base[i] = as_multipolygon(area.difference(carried))
    if on_platform or pending.is_empty:
        return StackSupport(base, interface)
    # Columns open at the base of a sub-part resting on its parent: dropped whole.
    return StackSupport([as_multipolygon(a.difference(pending)) for a in base],
                        [as_multipolygon(a.difference(pending)) for a in interface],
                        float(pending.area))


def support_paths(base: MultiPolygon, interface: MultiPolygon, settings: SupportSettings,
                  bead_width: float, height: float, bead_model: str) -> list[Path2D]:
    """One layer's support: sparse lines `settings.spacing` apart, solid interface lines."""
    paths = []
    if not base.is_empty:
        paths += zigzag(base, settings.spacing, SUPPORT_ANGLE, bead_width, "support")
    if not interface.is_empty:
        paths += zigzag(interface, bead_spacing(bead_width, height, bead_model),
                        INTERFACE_ANGLE, bead_width, "support_interface")
    return paths
