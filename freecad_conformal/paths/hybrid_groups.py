"""3-D layers of a hybrid plan deposited a few at a time, faced once (paths/hybrid.py).

The published hybrid method deposits each 3-D layer as a uniform nominal layer and faces its
top before the next: one milling session, two process switches, per 3-D layer (the 45°
branch: 27 of them, 55 of its 57 switches). Facing removes whatever lies above the target
plane, so what is deposited below it need not follow the turning planes one by one: a run
of 3-D layers from the lower plane P_a (the top of the layer before the run) to the top
plane P_b of its last layer is deposited as planar layers parallel to P_a, uniformly thick
(at most `d_max`), each kept where its base lies below P_b, and faced once to P_b. The
next run starts on that face.

A run stops growing when the next 3-D layer would
- turn P_b more than `GROUP_TURN` from P_a (beyond it the planar layers stand on P_a's
  frame across a wider wedge and waste more deposit in the last layer's overshoot);
- make the wedge between P_a and P_b thicker than the finishing tool's flutes reach;
- leave one of the planar layers overhanging the one below by more than the overhang angle
  (the reason the planes turn at all: a lean the run's frame cannot print).
A run of one 3-D layer stays as it was (its nominal layer is the same thing).
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np
from shapely.geometry import MultiPolygon, Polygon

from freecad_conformal.geometry.frames import angle_between
from freecad_conformal.geometry.sections import PlanarSlicer
from freecad_conformal.layers.model import Layer, as_multipolygon

#: A run of 3-D layers turns at most this much from its lower plane (see the docstring):
#: ten degrees keep a wall that follows the axis within 10° of the run's frame.
GROUP_TURN = math.radians(10.0)

#: A planar layer may reach past the one below by this much beyond the overhang rule's
#: width (mm²) before the run stops: sections of one smooth wall differ by rounding only.
OVERHANG_SLACK = 1e-2


@dataclass
class GroupedStack:
    """A sub-part's layers with runs of 3-D layers replaced by planar layers; `faces[k]` is
    the plane (point, normal) faced after layer k, and the index of the run's first layer."""

    layers: list[Layer]
    faces: dict[int, tuple[np.ndarray, np.ndarray, int]] = field(default_factory=dict)
    #: (3-D layers replaced, runs) for the report
    replaced: tuple[int, int] = (0, 0)


def _boundary_points(layer: Layer) -> np.ndarray:
    rings = [np.asarray(p.exterior.coords) for p in layer.region.geoms]
    return np.vstack([layer.frame.to_3d(ring, layer.section_height) for ring in rings])


def wedge_height(layers: Sequence[Layer], point_a: np.ndarray, normal_a: np.ndarray,
                 point_b: np.ndarray, normal_b: np.ndarray) -> float:
    """The largest height (along `normal_a`) of plane b above plane a over the layers'
    sections (their outlines, projected onto b along a)."""
    points = np.vstack([_boundary_points(layer) for layer in layers if not layer.region.is_empty])
    # x + t·n_a on plane b: t = (p_b − x)·n_b / (n_a·n_b)
    t = ((point_b - points) @ normal_b) / float(normal_a @ normal_b)
    return float((((points - point_a) @ normal_a) + t).max())


def _below_plane(region: MultiPolygon, frame, height: float, point_b: np.ndarray,
                 normal_b: np.ndarray) -> MultiPolygon:
    """The part of `region` (frame coordinates at `height`) lying below plane b."""
    a, b = float(frame.u @ normal_b), float(frame.v @ normal_b)
    c = float(point_b @ normal_b) - height * float(frame.n @ normal_b)
    if math.hypot(a, b) < 1e-12:
        return region if c > 0 else MultiPolygon()
    x0, y0, x1, y1 = region.bounds
    box = [(x0 - 1, y0 - 1), (x1 + 1, y0 - 1), (x1 + 1, y1 + 1), (x0 - 1, y1 + 1)]
    kept = []
    # Sutherland-Hodgman against a·u + b·v <= c
    for k, p in enumerate(box):
        q = box[(k + 1) % 4]
        fp, fq = a * p[0] + b * p[1] - c, a * q[0] + b * q[1] - c
        if fp <= 0:
            kept.append(p)
        if (fp < 0 < fq) or (fq < 0 < fp):
            s = fp / (fp - fq)
            kept.append((p[0] + s * (q[0] - p[0]), p[1] + s * (q[1] - p[1])))
    if len(kept) < 3:
        return MultiPolygon()
    return as_multipolygon(region.intersection(Polygon(kept)))


def _planar_run(slicer: PlanarSlicer, subpart: int, point_a: np.ndarray, height: float,
                point_b: np.ndarray, normal_b: np.ndarray, d_max: float) -> list[Layer]:
    """Planar layers from plane a (slicer's frame) up `height`, each kept below plane b."""
    frame = slicer.frame
    count = max(1, int(math.ceil(height / d_max - 1e-9)))
    thickness = height / count
    base = float(point_a @ frame.n)
    sections = slicer.sections([base + (j + 0.5) * thickness for j in range(count)])
    layers = []
    for j, section in enumerate(sections):
        region = as_multipolygon(section.polygons()) if not section.is_empty else MultiPolygon()
        region = _below_plane(region, frame, base + j * thickness, point_b, normal_b)
        if region.is_empty:
            continue
        layers.append(Layer(subpart=subpart, index=-1, frame=frame,
                            section_height=base + (j + 0.5) * thickness, region=region,
                            top_point=point_a + (j + 1) * thickness * frame.n,
                            top_normal=frame.n.copy(), thickness_min=thickness,
                            thickness_max=thickness))
    return layers


def _self_supporting(layers: Sequence[Layer], angle: float) -> bool:
    for lower, upper in zip(layers, layers[1:]):
        reach = lower.thickness_max * math.tan(angle)
        beyond = upper.region.difference(lower.region.buffer(reach, quad_segs=8))
        if beyond.area > OVERHANG_SLACK:
            return False
    return True


def group_tilted(shape, stack: Sequence[Layer], d_max: float, reach: float,
                 overhang_angle: float,
                 slicer_for: Callable[[np.ndarray], PlanarSlicer] | None = None) -> GroupedStack:
    """The sub-part's stack with runs of 3-D layers grouped (see the module docstring);
    `reach` is the finishing tool's flute length, `overhang_angle` in radians."""
    if slicer_for is None and stack:
        # one validated slicer, turned per run (checking a B-spline solid again per normal
        # costs more than its sections: layers/tilted.py)
        slicer_for = PlanarSlicer(shape, stack[0].frame.n).turned
    out: list[Layer] = []
    faces: dict[int, tuple[np.ndarray, np.ndarray, int]] = {}
    replaced = runs = 0
    i = 0
    while i < len(stack):
        layer = stack[i]
        if not layer.tilted or i == 0:
            out.append(layer)
            i += 1
            continue
        point_a = np.asarray(stack[i - 1].top_point, dtype=float)
        normal_a = np.asarray(stack[i - 1].top_normal, dtype=float)
        slicer = slicer_for(normal_a)
        best: tuple[int, list[Layer]] | None = None
        end = i
        while end < len(stack) and stack[end].tilted:
            last = stack[end]
            if angle_between(normal_a, last.top_normal) > GROUP_TURN:
                break
            height = wedge_height(stack[i:end + 1], point_a, normal_a,
                                  np.asarray(last.top_point), np.asarray(last.top_normal))
            if height > reach:
                break
            planar = _planar_run(slicer, layer.subpart, point_a, height,
                                 np.asarray(last.top_point), np.asarray(last.top_normal), d_max)
            if not planar or not _self_supporting(planar, overhang_angle):
                break
            best = (end, planar)
            end += 1
        if best is None or best[0] == i:
            out.append(layer)       # a run of one: its own nominal layer
            i += 1
            continue
        end, planar = best
        out.extend(planar)
        faces[len(out) - 1] = (np.asarray(stack[end].top_point, dtype=float),
                               np.asarray(stack[end].top_normal, dtype=float),
                               len(out) - len(planar))
        replaced += end - i + 1
        runs += 1
        i = end + 1
    out = [layer if layer.index == k else dataclasses.replace(layer, index=k)
           for k, layer in enumerate(out)]
    return GroupedStack(out, faces, (replaced, runs))
