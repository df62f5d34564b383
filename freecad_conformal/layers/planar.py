"""Planar layers of one sub-part: uniform, adaptive (volume difference or cusp height).

Criteria (METHODS section 3):
- uniform: thickness `layer` along the build direction;
- adaptive volume difference: the thickest Δ in [ΔL_min, ΔL_max], shrinking Δ ← Δ − Δ/4,
  whose volume difference `Δ · area(A_low △ A_up) / 2` (the volume between a straight wall
  and a prism on either end section) stays under `max_volume_difference`;
- adaptive cusp height: the thickest Δ whose cusp `Δ · |n·d|` over the surfaces crossing
  the slab stays under `max_cusp` (faces parallel to the layers excluded).
"""
from __future__ import annotations

import math
from typing import Sequence

import numpy as np
from shapely.geometry import MultiPolygon

from freecad_conformal.errors import PlanError
from freecad_conformal.geometry.polyhedral import PolyhedronSlicer
from freecad_conformal.geometry.sections import PlanarSection, PlanarSlicer, nudged_off
from freecad_conformal.layers.model import (BOUNDARY_INSET, SHRINK, Layer, LayerSettings,
                                            as_multipolygon)

#: A face whose normal is within 1° of the build direction is parallel to the layers: it
#: lies on a layer boundary and makes no cusp, so the cusp criterion ignores it.
FLAT_FACE_COS = math.cos(math.radians(1.0))

#: Tessellation tolerance (mm) for the cusp criterion's surface normals: 0.05 mm keeps
#: curved walls' normals within a degree or so for radii above a few mm.
CUSP_MESH_TOLERANCE = 0.05


def planar_bounds(shape, slicer: PlanarSlicer, low: float, high: float,
                  settings: LayerSettings) -> list[tuple[float, float]]:
    """(bottom, top) of each slab between `low` and `high` along the slicer's direction, by
    the settings' mode."""
    if settings.mode == "uniform":
        return _uniform_bounds(low, high, settings.thickness)
    if settings.mode == "adaptive":
        return _adaptive_bounds(slicer, low, high, settings)
    return _cusp_bounds(shape, slicer.frame.n, low, high, settings)


def _uniform_bounds(low: float, high: float, thickness: float) -> list[tuple[float, float]]:
    """Slabs of `thickness` from the base; the last keeps its mid-plane inside the part."""
    count = max(1, int(math.floor((high - low) / thickness + 0.5)))
    return [(low + k * thickness, low + (k + 1) * thickness) for k in range(count)]


def planar_layers(subpart: int, slicer: PlanarSlicer,
                  bounds: Sequence[tuple[float, float]], workers: int = 1) -> list[Layer]:
    middles = slicer.off_vertices([0.5 * (a + b) for a, b in bounds])
    sections = slicer.sections(middles, workers=workers, with_loops=True)
    regions = [as_multipolygon(section.polygons()) if not section.is_empty else MultiPolygon()
               for section in sections]
    return _stack(subpart, slicer, bounds, [s.height for s in sections], regions)


def polyhedral_layers(subpart: int, slicer: PlanarSlicer, quick: PolyhedronSlicer,
                      bounds: Sequence[tuple[float, float]]) -> list[Layer]:
    """`planar_layers` of a solid of polygon faces, its sections made from its vertices
    (`geometry/polyhedral.py`: the same regions within 1e-12 mm², a few times faster); a
    plane the quick cut leaves is cut the exact way. For the coarse ranking of orientations
    (`sampled_layers`): the exact stack a plan builds is always cut by `planar_layers`."""
    heights = nudged_off([0.5 * (a + b) for a, b in bounds], quick.clear_of_vertices)
    regions = [quick.section(h) for h in heights]
    missing = [k for k, region in enumerate(regions) if region is None]
    if missing:
        for k, section in zip(missing, slicer.sections([heights[k] for k in missing])):
            regions[k] = (as_multipolygon(section.polygons()) if not section.is_empty
                          else MultiPolygon())
    return _stack(subpart, slicer, bounds, heights, regions)


def _stack(subpart: int, slicer: PlanarSlicer, bounds: Sequence[tuple[float, float]],
           heights: Sequence[float], regions: Sequence[MultiPolygon]) -> list[Layer]:
    frame = slicer.frame
    layers = []
    for (bottom, top), height, region in zip(bounds, heights, regions):
        if region.is_empty:
            continue
        layers.append(Layer(subpart=subpart, index=len(layers), frame=frame,
                            section_height=height, region=region,
                            top_point=top * frame.n, top_normal=frame.n,
                            thickness_min=top - bottom, thickness_max=top - bottom))
    if not layers:
        raise PlanError(f"sub-part {subpart} has no material between {bounds[0][0]:.3f} and "
                        f"{bounds[-1][1]:.3f} mm along {np.round(frame.n, 4).tolist()}")
    return layers


def volume_difference(lower: PlanarSection, upper: PlanarSection, thickness: float) -> float:
    """Δ · area(A_low △ A_up) / 2: the volume a prism on either end section misses or adds."""
    a = as_multipolygon(lower.polygons()) if not lower.is_empty else MultiPolygon()
    b = as_multipolygon(upper.polygons()) if not upper.is_empty else MultiPolygon()
    return 0.5 * thickness * float(a.symmetric_difference(b).area)


def _adaptive_bounds(slicer: PlanarSlicer, low: float, high: float,
                     settings: LayerSettings) -> list[tuple[float, float]]:
    """Volume-difference adaptive slabs: one batched Boolean per layer for all trial tops."""
    d_min, d_max = settings.bounds
    trials = [d_max * (1.0 - SHRINK) ** k for k in range(64) if d_max * (1.0 - SHRINK) ** k >= d_min]
    if trials[-1] > d_min:
        trials.append(d_min)
    bounds: list[tuple[float, float]] = []
    bottom = low
    lower = slicer.section(low + BOUNDARY_INSET)
    while high - bottom > BOUNDARY_INSET:
        remaining = high - bottom
        candidates = [min(t, remaining) for t in trials]
        candidates = sorted(set(candidates), reverse=True)
        tops = [min(bottom + t, high - BOUNDARY_INSET) for t in candidates]
        uppers = slicer.sections(tops)
        chosen, upper = candidates[-1], uppers[-1]
        for thickness, section in zip(candidates, uppers):
            if volume_difference(lower, section, thickness) <= settings.max_volume_difference:
                chosen, upper = thickness, section
                break
        stretched = _absorb_sliver(chosen, remaining, d_min, d_max)
        if stretched != chosen and high - (bottom + stretched) > BOUNDARY_INSET:
            upper = slicer.section(bottom + stretched)
        bounds.append((bottom, bottom + stretched))
        bottom += stretched
        lower = upper
    return bounds


def _absorb_sliver(chosen: float, remaining: float, d_min: float, d_max: float) -> float:
    """Never leave a last layer thinner than ΔL_min: stretch this one or split the rest evenly."""
    rest = remaining - chosen
    if rest <= 0 or rest >= d_min:
        return chosen
    if remaining <= d_max:
        return remaining
    return 0.5 * remaining


def _cusp_bounds(shape, direction: np.ndarray, low: float, high: float,
                 settings: LayerSettings) -> list[tuple[float, float]]:
    """Cusp-height adaptive slabs from the slope of the tessellated surface."""
    d_min, d_max = settings.bounds
    slope_heights, slopes = _surface_slopes(shape, direction)
    bounds: list[tuple[float, float]] = []
    bottom = low
    while high - bottom > BOUNDARY_INSET:
        thickness = d_max
        while thickness > d_min:
            inside = (slope_heights[:, 1] >= bottom) & (slope_heights[:, 0] <= bottom + thickness)
            worst = float(slopes[inside].max()) if inside.any() else 0.0
            if thickness * worst <= settings.max_cusp:
                break
            thickness = max(d_min, thickness * (1.0 - SHRINK))
        remaining = high - bottom
        chosen = _absorb_sliver(min(thickness, remaining), remaining, d_min, d_max)
        bounds.append((bottom, bottom + chosen))
        bottom += chosen
    return bounds


def _surface_slopes(shape, direction: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(t, 2) height range and (t,) |n·d| of every non-flat surface triangle."""
    vertices, triangles = shape.tessellate(CUSP_MESH_TOLERANCE)
    points = np.array([tuple(v) for v in vertices], dtype=float)
    tri = np.array(triangles, dtype=np.int64).reshape(-1, 3)
    corners = points[tri]
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    lengths = np.linalg.norm(normals, axis=1)
    keep = lengths > 0
    cosines = np.abs(normals[keep] @ direction) / lengths[keep]
    heights = corners[keep] @ direction
    ranges = np.column_stack((heights.min(axis=1), heights.max(axis=1)))
    sloped = cosines < FLAT_FACE_COS
    return ranges[sloped], cosines[sloped]
