"""3-D layers: section planes that tilt to follow a bending centroidal axis (METHODS section 3).

From the current plane (point C_low, the section's centroid, normal D_low) the local axis
direction D_up points at the centroid of the section Δ further along D_low. The next plane
passes through C_low + Δ·D_up with normal D_up. If the slab between the planes is thinner
than ΔL_min or thicker than ΔL_max anywhere over the section, D_up is bisected towards
D_low (D_up ← (D_up + D_low)/2) until it fits or the two are within `PARALLEL_ANGLE`; then
Δ shrinks by a quarter and the search repeats. A slab that cannot fit even at ΔL_min is
refused with a PlanError naming the layer and its thickness range.
"""
from __future__ import annotations

import math

import numpy as np
from shapely.geometry import MultiPolygon

from freecad_conformal.errors import PlanError
from freecad_conformal.geometry.frames import unit
from freecad_conformal.geometry.sections import PlanarSection, PlanarSlicer, extent_along
from freecad_conformal.planning.layers import (BOUNDARY_INSET, SHRINK, Layer, LayerSettings,
                                               as_multipolygon)
from freecad_conformal.planning.subparts import SubPart

#: Window (mm along the axis) over which centroid drift is measured to tell a bend: short
#: enough to see a bend of a few centimetres' radius, long enough to smooth polygon noise.
BEND_WINDOW = 2.0

#: The axis bends when the drift over the window leans this much from the build direction;
#: below 3° tilting gains nothing a planar layer does not already print support-free.
BEND_MIN_ANGLE = math.radians(3.0)

#: Drift leaning more than 45° is a jump of the centroid (a column on a wider base, a
#: sudden change the decomposition splits at), not a bend to follow.
BEND_MAX_ANGLE = math.radians(45.0)

#: A window whose area changes by more than this ratio is a geometric change, not a bend.
BEND_AREA_RATIO = 1.25

#: Planes closer than this angle count as parallel: bisection stops there (METHODS' ε).
PARALLEL_ANGLE = math.radians(0.1)

#: Bisections needed to go from 90° to `PARALLEL_ANGLE` (90° / 2^k < 0.1°), plus the
#: final parallel try and margin.
MAX_BISECTIONS = 14


def axis_bends(layers: list[Layer]) -> bool:
    """True when the centroids of successive planar layers drift as along a bent axis."""
    if len(layers) < 2:
        return False
    thickness = max(layers[0].thickness, 1e-9)
    window = max(1, int(round(BEND_WINDOW / thickness)))
    n = layers[0].frame.n
    centroids = np.array([layer.to_3d(np.array([layer.region.centroid.coords[0]]))[0]
                          for layer in layers])
    areas = np.array([layer.area for layer in layers])
    islands = np.array([len(layer.region.geoms) for layer in layers])
    for k in range(len(layers) - window):
        if islands[k] != 1 or islands[k + window] != 1:
            continue
        ratio = areas[k + window] / areas[k]
        if not 1.0 / BEND_AREA_RATIO <= ratio <= BEND_AREA_RATIO:
            continue
        drift = centroids[k + window] - centroids[k]
        length = float(np.linalg.norm(drift))
        if length == 0.0:
            continue
        angle = math.acos(float(np.clip(drift @ n / length, -1.0, 1.0)))
        if BEND_MIN_ANGLE <= angle <= BEND_MAX_ANGLE:
            return True
    return False


class _Sections:
    """Sections of one sub-part by planes of any normal (one slicer per normal, cached)."""

    def __init__(self, shape) -> None:
        self.shape = shape
        self._slicers: dict[tuple[float, ...], PlanarSlicer] = {}

    def at(self, point: np.ndarray, normal: np.ndarray) -> PlanarSection:
        key = tuple(np.round(normal, 12))
        slicer = self._slicers.get(key)
        if slicer is None:
            slicer = self._slicers[key] = PlanarSlicer(self.shape, normal)
        return slicer.section(float(point @ slicer.frame.n))


def _points_3d(section: PlanarSection) -> np.ndarray:
    return np.concatenate([section.frame.to_3d(loop.points, section.height) for loop in section.loops])


def slab_thickness(lower: PlanarSection, lower_point: np.ndarray, lower_normal: np.ndarray,
                   upper: PlanarSection, upper_point: np.ndarray,
                   upper_normal: np.ndarray) -> tuple[float, float]:
    """(min, max) distance between the two planes over both sections' boundary points."""
    up = (_points_3d(upper) - lower_point) @ lower_normal
    down = (upper_point - _points_3d(lower)) @ upper_normal
    both = np.concatenate((up, down))
    return float(both.min()), float(both.max())


def _angle(a: np.ndarray, b: np.ndarray) -> float:
    return math.acos(float(np.clip(a @ b, -1.0, 1.0)))


def tilted_layers(subpart: SubPart, slicer: PlanarSlicer, low: float, high: float,
                  settings: LayerSettings) -> list[Layer]:
    """3-D layers of a sub-part whose centroidal axis bends (see the module docstring)."""
    d_min, d_max = settings.bounds
    nominal = settings.thickness if settings.mode == "uniform" else d_max
    sections = _Sections(subpart.shape)
    normal = slicer.frame.n
    lower = _first_section(slicer, low, high, nominal)
    plane_point = lower.height * normal
    centroid = lower.centroid
    layers: list[Layer] = []
    while True:
        step = _next_plane(sections, lower, plane_point, centroid, normal, nominal, d_min, d_max,
                           subpart.index, len(layers))
        if step is None:
            break
        upper, upper_point, upper_normal, thin, thick = step
        layers.append(_layer(sections, subpart.index, len(layers), plane_point, normal, upper_point,
                             upper_normal, thin, thick))
        lower, plane_point, normal, centroid = upper, upper_point, upper_normal, upper.centroid
    layers.extend(_planar_top(subpart, sections, plane_point, normal, nominal, d_min, len(layers)))
    if not layers:
        raise PlanError(f"sub-part {subpart.index}: no 3-D layer fits between {d_min:g} and {d_max:g} mm")
    return layers


def _first_section(slicer: PlanarSlicer, low: float, high: float, step: float) -> PlanarSection:
    """The lowest non-empty section (a part may touch its base plane only at a point or an
    edge, where the section at the base is empty)."""
    height = low + BOUNDARY_INSET
    while height < high:
        section = slicer.section(height)
        if not section.is_empty:
            return section
        height += step
    raise PlanError(f"no material found along {np.round(slicer.frame.n, 4).tolist()} "
                    f"between {low:.3f} and {high:.3f} mm")


def _next_plane(sections: _Sections, lower: PlanarSection, plane_point: np.ndarray,
                centroid: np.ndarray, normal: np.ndarray, nominal: float, d_min: float,
                d_max: float, subpart: int, index: int):
    """The next plane (section, point, normal, thinnest, thickest), or None at the top."""
    thickness = nominal
    worst: tuple[float, float] | None = None
    while thickness >= d_min - 1e-12:
        probe = sections.at(centroid + thickness * normal, normal)
        if probe.is_empty:
            return None
        drift = probe.centroid - centroid
        direction = unit(drift, "centroidal axis") if np.linalg.norm(drift) > 0 else normal
        if _angle(direction, normal) > BEND_MAX_ANGLE:
            direction = normal
        for _ in range(MAX_BISECTIONS):
            point = centroid + thickness * direction
            upper = sections.at(point, direction)
            if upper.is_empty:
                return None
            thin, thick = slab_thickness(lower, plane_point, normal, upper, point, direction)
            if d_min - 1e-9 <= thin and thick <= d_max + 1e-9:
                return upper, point, direction, thin, thick
            worst = (thin, thick)
            if direction is normal:
                break
            direction = unit(direction + normal, "bisected axis direction")
            if _angle(direction, normal) < PARALLEL_ANGLE:
                direction = normal      # the last try is exactly parallel: it fits any Δ in bounds
        thickness -= SHRINK * thickness
    thin, thick = worst if worst is not None else (float("nan"), float("nan"))
    raise PlanError(f"layer {index} of sub-part {subpart} would be {thin:.4f} to {thick:.4f} mm "
                    f"thick at best, outside [{d_min:g}, {d_max:g}] mm: the axis bends too "
                    "sharply for these bounds; widen them or split the sub-part")


def _layer(sections: _Sections, subpart: int, index: int, lower_point: np.ndarray,
           lower_normal: np.ndarray, upper_point: np.ndarray, upper_normal: np.ndarray,
           thin: float, thick: float) -> Layer:
    """The slab's region is cut on the bisecting plane halfway between the two planes."""
    mid_normal = unit(lower_normal + upper_normal, "middle plane normal")
    mid_point = 0.5 * (lower_point + upper_point)
    section = sections.at(mid_point, mid_normal)
    region = as_multipolygon(section.polygons()) if not section.is_empty else MultiPolygon()
    return Layer(subpart=subpart, index=index, frame=section.frame, section_height=section.height,
                 region=region, top_point=upper_point, top_normal=upper_normal,
                 thickness_min=thin, thickness_max=thick)


def _planar_top(subpart: SubPart, sections: _Sections, plane_point: np.ndarray, normal: np.ndarray,
                nominal: float, d_min: float, first_index: int) -> list[Layer]:
    """Parallel layers for what is left above the last tilted plane (thinner than a step)."""
    _, top = extent_along(subpart.shape, normal)
    base = float(plane_point @ normal)
    remaining = top - base
    if remaining < max(d_min, BOUNDARY_INSET):
        return []
    count = max(1, int(round(remaining / nominal)))
    thickness = remaining / count
    layers = []
    for k in range(count):
        mid = base + (k + 0.5) * thickness
        section = sections.at(mid * normal, normal)
        if section.is_empty:
            continue
        layers.append(Layer(subpart=subpart.index, index=first_index + len(layers), frame=section.frame,
                            section_height=section.height,
                            region=as_multipolygon(section.polygons()),
                            top_point=plane_point + (k + 1) * thickness * normal, top_normal=normal,
                            thickness_min=thickness, thickness_max=thickness))
    return layers
