"""Layers that hold the whole part, for a plan that mills the deposit to shape (hybrid).

An additive layer stands for its slab by the section at its middle: a wall that leans or
curves within the slab is built as the slicer's usual staircase, and the last slab of a
uniform stack keeps its middle inside the part, so up to half a layer of a sloped or domed
top is not built at all. A milled plan must deposit everything the part holds (the mill
only removes), so each planar layer here deposits the union of the sections at its slab's
bottom, middle and top, and a layer is added on the stack where the part reaches past the
last slab's top (the mill takes what it leaves above the part).
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import shapely

from freecad_conformal.decomposition.subparts import SubPart
from freecad_conformal.geometry.frames import unit
from freecad_conformal.geometry.sections import PlanarSlicer, extent_along
from freecad_conformal.layers.model import Layer, as_multipolygon

#: Sections at a slab's ends are cut this far (mm) inside it: a plane exactly on a face
#: that bounds the slab (the underside of a T's arms at a layer boundary) belongs to the
#: slab above, not to this one.
END_INSET = 1e-3


def covering_layers(layers: list[Layer], slicer: PlanarSlicer, low: float, high: float,
                    workers: int = 1) -> list[Layer]:
    """`layers` (those planar along the slicer's direction, from `low` to about `high`)
    widened to hold the part over their slabs, with a layer on top where the part reaches
    past the last one. Others are kept as they are: 3-D layers (their nominal layers are
    faced) and planar ones along other directions (`covering_stack` takes those)."""
    n = slicer.frame.n
    planar = [k for k, layer in enumerate(layers)
              if not layer.tilted and float(layer.frame.n @ n) > 1.0 - 1e-12]
    if not planar:
        return list(layers)
    spans = []
    for k in planar:
        top = float(layers[k].top_point @ n)
        bottom = top - layers[k].thickness_max
        spans.append((max(bottom + END_INSET, low + END_INSET), min(top - END_INSET, high - END_INSET)))
    last = layers[planar[-1]]
    last_top = float(last.top_point @ n)
    extra = high - last_top > END_INSET and planar[-1] == len(layers) - 1
    heights = [h for span in spans for h in span]
    if extra:
        heights.append(min(last_top + 0.5 * last.thickness_max, high - END_INSET))
    sections = slicer.sections(slicer.off_vertices(heights), workers=workers)
    out = list(layers)
    for j, k in enumerate(planar):
        layer = layers[k]
        ends = [s for s in sections[2 * j:2 * j + 2] if not s.is_empty]
        # the slicer's frame is the planar layers' own
        parts = [layer.region] + [as_multipolygon(s.polygons()) for s in ends]
        out[k] = replace(layer, region=as_multipolygon(shapely.union_all(parts)))
    if extra and not sections[-1].is_empty:
        top = last_top + last.thickness_max
        out.append(replace(last, index=len(out), section_height=sections[-1].height,
                           region=as_multipolygon(sections[-1].polygons()),
                           top_point=top * n, volume_difference=0.0))
    return out


def covering_stack(subpart: SubPart, layers: list[Layer], workers: int = 1) -> list[Layer]:
    """`covering_layers` of one sub-part's stack, for each direction its planar layers
    take (past a bend the planes follow the axis, parallel again)."""
    directions: list[np.ndarray] = []
    for layer in layers:
        if not layer.tilted and not any(float(layer.frame.n @ d) > 1.0 - 1e-12
                                        for d in directions):
            directions.append(layer.frame.n)
    for direction in directions:
        slicer = PlanarSlicer(subpart.shape, unit(direction))
        low, high = extent_along(subpart.shape, slicer.frame.n)
        layers = covering_layers(layers, slicer, low, high, workers)
    return layers
