"""The layer model: how to slice (`LayerSettings`) and one slab of a sub-part (`Layer`).

A `Layer` is the slab between two planes. Its `region` is the exact section at the slab's
middle plane (the usual slicer choice: area × thickness integrates the volume with midpoint
accuracy), as a shapely MultiPolygon in that plane's frame; the tool tip deposits on the
slab's *top* plane with the tool axis along the top plane's normal.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np
from shapely.geometry import MultiPolygon

from freecad_conformal.errors import PlanError
from freecad_conformal.geometry.frames import LayerFrame
from freecad_conformal.tolerances import ROUNDING_SLACK

MODES = ("uniform", "adaptive", "cusp")

#: The first and last section planes stay this far inside the sub-part (mm) so that a plane
#: never lies on its base or top face, where the section would be the face itself or empty.
BOUNDARY_INSET = 1e-4

#: Each failed adaptive trial shrinks the thickness by this fraction (METHODS: Δ ← Δ − Δ/4).
SHRINK = 0.25

@dataclass
class LayerSettings:
    """How to slice a sub-part.

    Attributes:
        mode: "uniform", "adaptive" (volume difference) or "cusp".
        thickness: uniform layer thickness (mm); also the nominal one of 3-D layers.
        min_thickness, max_thickness: ΔL_min, ΔL_max (mm); default 0.5× and 1.5× `thickness`.
        max_volume_difference: adaptive limit per layer (mm³).
        max_cusp: cusp-height limit (mm).
        tilt: let planes tilt where the centroidal axis bends ("3-D" layers): in a
            sub-part that planar layers would leave overhanging, where following the bend
            is estimated to spare a real share of that, and where the sections move
            sideways keeping their shape and are narrow enough to turn within the
            thickness bounds (`layers/plan.needs_tilt`, `layers/following.py`,
            `layers/tilted.axis_bends`); elsewhere the layers stay planar.
        workers: processes cutting the sections at once (0: `section_pool.useful_workers`
            decides); the layers are the same whatever the count.
    """

    mode: str = "uniform"
    thickness: float = 0.2
    min_thickness: float | None = None
    max_thickness: float | None = None
    max_volume_difference: float = 2.0
    max_cusp: float = 0.05
    tilt: bool = True
    workers: int = 0

    @property
    def bounds(self) -> tuple[float, float]:
        low = self.min_thickness if self.min_thickness is not None else 0.5 * self.thickness
        high = self.max_thickness if self.max_thickness is not None else 1.5 * self.thickness
        return float(low), float(high)

    def within_bead(self, width: float) -> "LayerSettings":
        """These settings for beads `width` wide: a maximum left to its default (1.5 x the
        layer height) is taken down to the bead width where it exceeds it, as no bead is
        taller than it is wide (0.3 mm adaptive layers of 0.4 mm beads reached 0.45 mm,
        and the bead model capped each such bead at a circle: a sparse print, silently).
        A maximum the user set is theirs (`jobs/plan.check_layers_fit_bead` refuses one
        above the bead); the minimum is never raised past it."""
        if self.max_thickness is not None or 1.5 * self.thickness <= width:
            return self
        return dataclasses.replace(self, max_thickness=max(width, self.bounds[0]))

    def validate(self, part_size: float | None = None) -> None:
        """Raise PlanError for thicknesses that are not positive, inverted or larger than the part."""
        if self.mode not in MODES:
            raise PlanError(f"layer mode {self.mode!r} is not one of {', '.join(MODES)}")
        low, high = self.bounds
        for name, value, default in (
                ("layer height", self.thickness, False),
                ("minimum layer height", low, self.min_thickness is None),
                ("maximum layer height", high, self.max_thickness is None)):
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise PlanError(f"{name} must be a positive number of mm, got {value!r}")
            if part_size is not None and value > part_size * (1.0 + ROUNDING_SLACK):
                # A bound left to its default says where it comes from: the user never set it.
                source = (f" ({'0.5' if name.startswith('minimum') else '1.5'} x the layer "
                          "height)") if default else ""
                raise PlanError(f"{name} {value:g} mm{source} is larger than the part "
                                f"({part_size:.3f} mm across at its thinnest)")
        low, high = self.bounds
        if low > high:
            raise PlanError(f"minimum layer height {low:g} mm exceeds the maximum {high:g} mm")
        if not isinstance(self.workers, int) or self.workers < 0:
            raise PlanError(f"workers must be a whole number, 0 or more, got {self.workers!r}")
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
        return mid + lift[:, None] * self.top_normal


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


def base_level(layers: Sequence[Layer]) -> float:
    """Level of a stack's first layer's bottom along its normal."""
    first = layers[0]
    return float(first.top_point @ first.top_normal) - first.thickness_min


def thickness_report(layers: Sequence[Layer]) -> tuple[float, float]:
    """(thinnest, thickest) slab thickness over all layers."""
    return (min(layer.thickness_min for layer in layers), max(layer.thickness_max for layer in layers))


def check_thickness(layers: Sequence[Layer], settings: LayerSettings) -> None:
    """Refuse any layer thinner than ΔL_min or thicker than ΔL_max, naming it."""
    low, high = settings.bounds
    slack = ROUNDING_SLACK
    for layer in layers:
        if layer.thickness_min < low - slack or layer.thickness_max > high + slack:
            raise PlanError(
                f"layer {layer.index} of sub-part {layer.subpart} is {layer.thickness_min:.4f} to "
                f"{layer.thickness_max:.4f} mm thick, outside [{low:g}, {high:g}] mm; "
                "widen the layer height bounds or use a smaller tilt")
