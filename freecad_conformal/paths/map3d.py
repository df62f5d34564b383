"""2D layer paths -> 3D tool poses, and the top/bottom skins of a sub-part's layers.

A layer's paths live in the (u, v) frame of its middle plane; the tool tip deposits on the
layer's top plane, reached along the top normal, which is also the tool axis (for planar
layers that is just "(u, v) at the top height"; for 3-D layers the projection follows the
tilt, so the bead height varies between the layer's minimum and maximum thickness).
"""
from __future__ import annotations

import math
from functools import cached_property
from dataclasses import dataclass
from typing import Sequence

import numpy as np
import shapely
from shapely.geometry import MultiPolygon

from freecad_conformal.paths.fill2d import Path2D, valid_region
from freecad_conformal.paths.scan import polygons_of
from freecad_conformal.layers.model import Layer, as_multipolygon

#: Two layer regions whose vertices agree this closely (mm) are the same region: sections of
#: a prismatic stretch come back vertex for vertex from OCC, and a millionth of a millimetre
#: is far below any bead, so the skin between them is empty without a GEOS Boolean (most of
#: a CAD part's layers: the table's 1,145 of 1,150).
SAME_REGION = 1e-6


@dataclass
class Path3D:
    """A deposition polyline: tool-tip points (N, 3), one tool axis, role and bead height."""

    points: np.ndarray
    axis: np.ndarray
    role: str
    subpart: int
    layer: int
    thickness: float
    closed: bool = False
    #: bead width where it is not the settings' (`Path2D.width`)
    width: float | None = None

    @cached_property
    def length(self) -> float:
        """Read by the cooling rule, the choice of runs to alternate and the summaries: once
        (the jack's plan read 21,625 lengths, 0.27 s on FreeCAD 1.0). The points are not
        changed after the path is made."""
        return float(np.linalg.norm(np.diff(self.points, axis=0), axis=1).sum())


def map_paths(layer: Layer, paths: Sequence[Path2D]) -> list[Path3D]:
    """Map a layer's ordered 2D paths onto its top plane with the tool along the top normal."""
    return [Path3D(points=layer.to_3d(path.points), axis=np.array(layer.top_normal, dtype=float),
                   role=path.role, subpart=layer.subpart, layer=layer.index,
                   thickness=layer.thickness, closed=path.closed, width=path.width)
            for path in paths]


def region_in(target: Layer, source: Layer, geometry=None) -> MultiPolygon:
    """`source`'s region (or `geometry`, in source's frame) expressed in `target`'s layer
    frame (projected along target's normal)."""
    geometry = source.region if geometry is None else geometry
    if source.frame is target.frame or (np.allclose(source.frame.u, target.frame.u)
                                        and np.allclose(source.frame.v, target.frame.v)):
        return geometry

    def move(uv: np.ndarray) -> np.ndarray:
        return target.frame.to_2d(source.frame.to_3d(uv, source.section_height))

    return as_multipolygon(shapely.transform(geometry, move).buffer(0))


def _boolean(a, b, operation: str):
    """a ∩ b or a − b; a section that came back invalid (self-touching rings of a Boolean
    fallback: the bottle along X) is repaired first rather than lose the plan."""
    try:
        return getattr(a, operation)(b)
    except shapely.errors.GEOSException:
        return getattr(valid_region(a), operation)(valid_region(b))


def skin_regions(layers: Sequence[Layer], top_layers: int, bottom_layers: int,
                 rests_on_parent: bool) -> list[MultiPolygon]:
    """Per layer, the area to print solid: not covered `top_layers` above or
    `bottom_layers` below within the sub-part. A sub-part that rests on its parent has no
    bottom skin (its base is inside the part, not on the bed)."""
    return [skin_at(layers, i, top_layers, bottom_layers, rests_on_parent)
            for i in range(len(layers))]


def skin_at(layers: Sequence[Layer], i: int, top_layers: int, bottom_layers: int,
            rests_on_parent: bool) -> MultiPolygon:
    """`skin_regions` of layer i alone (it reads the layers around it)."""
    layer = layers[i]
    covered = layer.region
    for offset in [*range(1, top_layers + 1), *(-k for k in range(1, bottom_layers + 1))]:
        j = i + offset
        if j < 0 and rests_on_parent:
            continue
        if not 0 <= j < len(layers):
            covered = MultiPolygon()
            break
        other = region_in(layer, layers[j])
        if covered is layer.region and shapely.equals_exact(other, covered, SAME_REGION):
            continue
        covered = _islandwise(covered, other, "intersection")
        if covered.is_empty:
            break
    return (MultiPolygon() if covered is layer.region
            else _islandwise(layer.region, covered, "difference"))


def _islandwise(a: MultiPolygon, b: MultiPolygon, operation: str) -> MultiPolygon:
    """a ∩ b or a − b, where the islands of `a` that `b` holds too (`SAME_REGION`) are kept
    (∩) or dropped (−) as they are, and only the others go through GEOS, against the islands
    of `b` left: the islands of one region do not overlap, so a matched pair meets no other
    island. GEOS is slowest on the edges that nearly coincide there: a mug's wall, the same
    ring on every layer beside its changing handle, took 3 ms a Boolean, 3.5 s of its 9 s
    plan."""
    if a.is_empty or b.is_empty:
        return a if operation == "difference" else MultiPolygon()
    if len(a.geoms) == 1 and len(b.geoms) == 1:
        if shapely.equals_exact(a, b, SAME_REGION):
            return a if operation == "intersection" else MultiPolygon()
        return as_multipolygon(_boolean(a, b, operation))
    mine, theirs = shapely.get_parts(a), shapely.get_parts(b)
    # Islands equal within SAME_REGION have boxes within it: those pairs are compared.
    near = np.abs(shapely.bounds(mine)[:, None, :] - shapely.bounds(theirs)[None, :, :])
    pairs = np.argwhere((near <= SAME_REGION).all(axis=2))
    same = np.zeros(len(mine), dtype=bool)
    taken = np.zeros(len(theirs), dtype=bool)
    for i, j in pairs:
        if not same[i] and not taken[j] and shapely.equals_exact(mine[i], theirs[j], SAME_REGION):
            same[i] = taken[j] = True
    if not same.any():
        return as_multipolygon(_boolean(a, b, operation))
    left, others = mine[~same], theirs[~taken]
    if not len(left):
        found = []
    elif not len(others):
        found = list(left) if operation == "difference" else []
    else:
        found = polygons_of(_boolean(MultiPolygon(list(left)), MultiPolygon(list(others)),
                                     operation))
    kept = list(mine[same]) if operation == "intersection" else []
    return MultiPolygon([*kept, *found])


def bridge_regions(layers: Sequence[Layer], skins: Sequence[MultiPolygon],
                   solid_below_area: float, bead_width: float | None = None) -> list[MultiPolygon]:
    """Per layer, the part of its solid area (`skins`) filled as bridges: over the layer
    below's sparse infill, its rows span the sparse grid's gaps, an internal bridge
    (PrusaSlicer prints it at bridge speed); with `bead_width`, also what lies over nothing
    (`air_at`: a closed cavity's ceiling, an overhang the plan leaves), as PrusaSlicer
    bridges it with supports off. Sparse pieces under `solid_below_area` print solid, so
    they carry no bridge; the first layer has none below."""
    return [bridge_at(layers, i, skins[i], skins[i - 1] if i else None, solid_below_area,
                      bead_width)
            for i in range(len(layers))]


#: Pieces of a layer over nothing narrower than this many bead widths are no bridge: the
#: step each layer of a wall within the allowed overhang angle makes past the one below
#: (0.2 mm at 45 degrees), which its perimeters lay.
AIR_MIN_WIDTHS = 2.0


def bridge_wide(area, bead_width: float) -> bool:
    """Whether `area` over nothing holds a part `AIR_MIN_WIDTHS` beads wide: a bridge to
    the fill (`_over_air`) and to the support (`support.bridged`) alike."""
    return not area.is_empty and not area.buffer(-0.5 * AIR_MIN_WIDTHS * bead_width).is_empty


def bridge_at(layers: Sequence[Layer], i: int, skin: MultiPolygon,
              below_skin: MultiPolygon | None, solid_below_area: float,
              bead_width: float | None = None) -> MultiPolygon:
    """`bridge_regions` of layer i alone, from its skin and the layer below's."""
    if i == 0 or skin.is_empty:
        return MultiPolygon()
    below, layer = layers[i - 1], layers[i]
    inside = MultiPolygon()
    if math.isfinite(solid_below_area):
        sparse = (below.region if below_skin.is_empty
                  else _boolean(below.region, below_skin, "difference"))
        pieces = [p for p in polygons_of(sparse) if p.area >= solid_below_area]
        if pieces:
            inside = as_multipolygon(_boolean(skin, region_in(layer, below, MultiPolygon(pieces)),
                                              "intersection"))
    air = _over_air(layer, below, skin, bead_width) if bead_width else MultiPolygon()
    if air.is_empty:
        return inside
    return air if inside.is_empty else as_multipolygon(_boolean(inside, air, "union"))


def _over_air(layer: Layer, below: Layer, skin: MultiPolygon, bead_width: float) -> MultiPolygon:
    """The pieces of `skin` (a layer's solid area, or its bridge) over nothing at least
    `AIR_MIN_WIDTHS` beads wide."""
    # What is over nothing lies in the skin: a skin with no part that wide holds none (the
    # slivers a curved wall's skin is on most layers: the bottle's 259 differences with
    # the layer below took 0.29 s).
    if not bridge_wide(skin, bead_width):
        return MultiPolygon()
    # The layer less the one below, island by island: where they hold the same islands
    # no GEOS Boolean is made.
    bare = _islandwise(layer.region, region_in(layer, below), "difference")
    if bare.is_empty:
        return MultiPolygon()
    bare = as_multipolygon(_boolean(bare, skin, "intersection"))
    return MultiPolygon([p for p in polygons_of(bare) if bridge_wide(p, bead_width)])


def air_at(layers: Sequence[Layer], i: int, bridge,
           bead_width: float | None) -> MultiPolygon | None:
    """The part of layer i's bridge over nothing (the layer below holds no material
    there): laid from anchor to anchor (`scan.bridge_angle`), where the internal
    bridges keep the infill's direction. None when it has none."""
    if bridge is None or i == 0 or bridge.is_empty or bead_width is None:
        return None
    bare = _over_air(layers[i], layers[i - 1], bridge, bead_width)
    return None if bare.is_empty else bare
