"""Layers of one sub-part: uniform, adaptive (volume difference or cusp height) and 3-D.

A `Layer` is the slab between two planes. Its `region` is the exact section at the slab's
middle plane (the usual slicer choice: area × thickness integrates the volume with midpoint
accuracy), as a shapely MultiPolygon in that plane's frame; the tool tip deposits on the
slab's *top* plane with the tool axis along the top plane's normal.

Criteria (METHODS section 3):
- uniform: thickness `layer` along the build direction;
- adaptive volume difference: the thickest Δ in [ΔL_min, ΔL_max], shrinking Δ ← Δ − Δ/4,
  whose volume difference `Δ · area(A_low △ A_up) / 2` (the volume between a straight wall
  and a prism on either end section) stays under `max_volume_difference`;
- adaptive cusp height: the thickest Δ whose cusp `Δ · |n·d|` over the surfaces crossing
  the slab stays under `max_cusp` (faces parallel to the layers excluded);
- 3-D layers: where the centroidal axis bends, successive planes tilt to follow it
  (`planning.tilted`); each layer reports its minimum and maximum thickness.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np
from shapely.geometry import MultiPolygon

from freecad_conformal.errors import PlanError
from freecad_conformal.geometry.frames import LayerFrame, unit
from freecad_conformal.geometry.sections import PlanarSection, PlanarSlicer, extent_along
from freecad_conformal.planning.subparts import SubPart

MODES = ("uniform", "adaptive", "cusp")

#: The first and last section planes stay this far inside the sub-part (mm) so that a plane
#: never lies on its base or top face, where the section would be the face itself or empty.
BOUNDARY_INSET = 1e-4

#: Each failed adaptive trial shrinks the thickness by this fraction (METHODS: Δ ← Δ − Δ/4).
SHRINK = 0.25

#: A face whose normal is within 1° of the build direction is parallel to the layers: it
#: lies on a layer boundary and makes no cusp, so the cusp criterion ignores it.
FLAT_FACE_COS = math.cos(math.radians(1.0))

#: Tessellation tolerance (mm) for the cusp criterion's surface normals: 0.05 mm keeps
#: curved walls' normals within a degree or so for radii above a few mm.
CUSP_MESH_TOLERANCE = 0.05


@dataclass
class LayerSettings:
    """How to slice a sub-part.

    Attributes:
        mode: "uniform", "adaptive" (volume difference) or "cusp".
        thickness: uniform layer thickness (mm); also the nominal one of 3-D layers.
        min_thickness, max_thickness: ΔL_min, ΔL_max (mm); default 0.5× and 1.5× `thickness`.
        max_volume_difference: adaptive limit per layer (mm³).
        max_cusp: cusp-height limit (mm).
        tilt: let planes tilt where the centroidal axis bends ("3-D" layers): where the
            sections move sideways keeping their shape and are narrow enough to turn
            within the thickness bounds (`planning.tilted.axis_bends`); elsewhere the
            layers stay planar.
    """

    mode: str = "uniform"
    thickness: float = 0.2
    min_thickness: float | None = None
    max_thickness: float | None = None
    max_volume_difference: float = 2.0
    max_cusp: float = 0.05
    tilt: bool = True

    @property
    def bounds(self) -> tuple[float, float]:
        low = self.min_thickness if self.min_thickness is not None else 0.5 * self.thickness
        high = self.max_thickness if self.max_thickness is not None else 1.5 * self.thickness
        return float(low), float(high)

    def validate(self, part_size: float | None = None) -> None:
        """Raise PlanError for thicknesses that are not positive, inverted or larger than the part."""
        if self.mode not in MODES:
            raise PlanError(f"layer mode {self.mode!r} is not one of {', '.join(MODES)}")
        for name, value in (("layer height", self.thickness), ("minimum layer height", self.bounds[0]),
                            ("maximum layer height", self.bounds[1])):
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise PlanError(f"{name} must be a positive number of mm, got {value!r}")
            if part_size is not None and value > part_size:
                raise PlanError(f"{name} {value:g} mm is larger than the part ({part_size:.3f} mm)")
        low, high = self.bounds
        if low > high:
            raise PlanError(f"minimum layer height {low:g} mm exceeds the maximum {high:g} mm")
        if self.mode == "uniform" and not low <= self.thickness <= high:
            raise PlanError(f"layer height {self.thickness:g} mm is outside [{low:g}, {high:g}] mm")
        for name, value in (("volume difference limit", self.max_volume_difference),
                            ("cusp height limit", self.max_cusp)):
            if not (math.isfinite(value) and value > 0):
                raise PlanError(f"{name} must be > 0, got {value!r}")


@dataclass
class Layer:
    """One slab of a sub-part.

    Attributes:
        subpart: index of the sub-part (BuildPlan.subparts).
        index: position in the sub-part's stack (0 on the base).
        frame: frame of the middle plane; `region` is in its (u, v) coordinates.
        section_height: height of the middle plane along `frame.n`.
        region: the section at the middle plane (islands with holes).
        top_point, top_normal: the top plane, where the tool tip deposits; the tool axis.
        thickness_min, thickness_max: extreme slab thickness over the region (mm).
        volume_difference: the adaptive criterion's value for this layer (mm³), if computed.
    """

    subpart: int
    index: int
    frame: LayerFrame
    section_height: float
    region: MultiPolygon = field(repr=False)
    top_point: np.ndarray
    top_normal: np.ndarray
    thickness_min: float
    thickness_max: float
    volume_difference: float = 0.0

    @property
    def thickness(self) -> float:
        """Mean thickness: the bead height that carries the flow."""
        return 0.5 * (self.thickness_min + self.thickness_max)

    @property
    def tilted(self) -> bool:
        return bool(abs(float(self.frame.n @ self.top_normal)) < 1.0 - 1e-12)

    @property
    def area(self) -> float:
        return float(self.region.area)

    def to_3d(self, uv: np.ndarray) -> np.ndarray:
        """Layer coordinates -> tool-tip points on the top plane (projected along its normal)."""
        mid = self.frame.to_3d(np.asarray(uv, dtype=float).reshape(-1, 2), self.section_height)
        lift = (self.top_point - mid) @ self.top_normal
        return mid + np.outer(lift, self.top_normal)


def as_multipolygon(geometry) -> MultiPolygon:
    """Any polygonal shapely geometry as a MultiPolygon (empty when it has no area)."""
    if geometry.is_empty:
        return MultiPolygon()
    if geometry.geom_type == "Polygon":
        return MultiPolygon([geometry])
    if geometry.geom_type == "MultiPolygon":
        return geometry
    polygons = [g for g in getattr(geometry, "geoms", []) if g.geom_type == "Polygon" and not g.is_empty]
    return MultiPolygon(polygons)


def plan_layers(subpart: SubPart, settings: LayerSettings) -> list[Layer]:
    """Layers of one sub-part along its build direction, in deposition order (none for a
    sliver thinner than ΔL_min; the job notes it).

    Raises:
        PlanError: bad settings, or a 3-D layer that cannot stay within [ΔL_min, ΔL_max].
    """
    settings.validate()
    direction = unit(subpart.build_direction, f"build direction of sub-part {subpart.index}")
    slicer = PlanarSlicer(subpart.shape, direction)
    low, high = extent_along(subpart.shape, slicer.frame.n)
    if settings.mode == "uniform":
        bounds = _uniform_bounds(low, high, settings.thickness)
    elif settings.mode == "adaptive":
        bounds = _adaptive_bounds(slicer, low, high, settings)
    else:
        bounds = _cusp_bounds(subpart.shape, slicer.frame.n, low, high, settings)
    if high - low < settings.bounds[0]:
        return []      # a sliver thinner than the thinnest layer: nothing a bead can build
    layers = _planar_layers(subpart.index, slicer, bounds)
    if settings.tilt and len(layers) > 2:
        from freecad_conformal.planning.tilted import axis_bends, tilted_layers

        if axis_bends(layers, settings.bounds):
            layers = tilted_layers(subpart, slicer, low, high, settings)
    return layers


def _uniform_bounds(low: float, high: float, thickness: float) -> list[tuple[float, float]]:
    """Slabs of `thickness` from the base; the last keeps its mid-plane inside the part."""
    count = max(1, int(math.floor((high - low) / thickness + 0.5)))
    return [(low + k * thickness, low + (k + 1) * thickness) for k in range(count)]


def _planar_layers(subpart: int, slicer: PlanarSlicer,
                   bounds: Sequence[tuple[float, float]]) -> list[Layer]:
    middles = [0.5 * (a + b) for a, b in bounds]
    sections = slicer.sections(middles)
    frame = slicer.frame
    layers = []
    for (bottom, top), section in zip(bounds, sections):
        region = as_multipolygon(section.polygons()) if not section.is_empty else MultiPolygon()
        if region.is_empty:
            continue
        layers.append(Layer(subpart=subpart, index=len(layers), frame=frame,
                            section_height=section.height, region=region,
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


def thickness_report(layers: Sequence[Layer]) -> tuple[float, float]:
    """(thinnest, thickest) slab thickness over all layers."""
    return (min(layer.thickness_min for layer in layers), max(layer.thickness_max for layer in layers))


def check_thickness(layers: Sequence[Layer], settings: LayerSettings) -> None:
    """Refuse any layer thinner than ΔL_min or thicker than ΔL_max, naming it."""
    low, high = settings.bounds
    slack = 1e-9
    for layer in layers:
        if layer.thickness_min < low - slack or layer.thickness_max > high + slack:
            raise PlanError(
                f"layer {layer.index} of sub-part {layer.subpart} is {layer.thickness_min:.4f} to "
                f"{layer.thickness_max:.4f} mm thick, outside [{low:g}, {high:g}] mm; "
                "widen the layer height bounds or use a smaller tilt")
