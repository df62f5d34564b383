"""Layers of one sub-part in deposition order: planar, or 3-D where the axis bends and
following it spares overhang planar layers would leave."""
from __future__ import annotations

from freecad_conformal.decomposition.planner import MIN_SAVING
from freecad_conformal.decomposition.subparts import SubPart
from freecad_conformal.errors import PlanError
from freecad_conformal.geometry.frames import unit
from freecad_conformal.geometry.sections import PlanarSlicer, extent_along
from freecad_conformal.layers.following import following_spares
from freecad_conformal.layers.model import Layer, LayerSettings
from freecad_conformal.geometry.polyhedral import PolyhedronSlicer
from freecad_conformal.layers.planar import planar_bounds, planar_layers, polyhedral_layers
from freecad_conformal.layers.tilted import axis_bends, tilted_layers


def _along_build_direction(subpart: SubPart,
                           settings: LayerSettings) -> tuple[PlanarSlicer, float, float]:
    """The settings checked, and the sub-part's slicer and exact extent along its build
    direction."""
    settings.validate()
    direction = unit(subpart.build_direction, f"build direction of sub-part {subpart.index}")
    slicer = PlanarSlicer(subpart.shape, direction)
    low, high = extent_along(subpart.shape, slicer.frame.n)
    return slicer, low, high


def plan_layers(subpart: SubPart, settings: LayerSettings) -> list[Layer]:
    """Layers of one sub-part along its build direction, in deposition order (none for a
    sliver thinner than ΔL_min; the job notes it).

    Raises:
        PlanError: bad settings, or a 3-D layer that cannot stay within [ΔL_min, ΔL_max].
    """
    slicer, low, high = _along_build_direction(subpart, settings)
    if high - low < settings.bounds[0]:
        return []      # a sliver thinner than the thinnest layer: nothing a bead can build
    layers = planar_layers(subpart.index, slicer,
                           planar_bounds(subpart.shape, slicer, low, high, settings),
                           settings.workers)
    if settings.tilt and len(layers) > 2 and needs_tilt(subpart):
        if axis_bends(layers, settings.bounds) and following_spares(subpart, layers):
            layers = tilted_layers(subpart, slicer, low, high, settings)
    return layers


def needs_tilt(subpart: SubPart) -> bool:
    """Whether 3-D layers could spare the sub-part support: only where planar layers along
    its build direction leave overhang (more than the decomposition leaves a piece whole
    with). A support-free sub-part gains nothing from tilting but costs: an oblique prism
    leaning 23° printed 4.13 cm³ in 28:07 on 115 tilted layers against 3.96 cm³ in 24:48
    planar, and took 10.6 s to plan instead of 3.3 s (three OCC cuts per tilted layer)."""
    return subpart.overhang_area > MIN_SAVING


def sampled_layers(subpart: SubPart, settings: LayerSettings,
                   every: int) -> tuple[list[Layer], float]:
    """Every `every`-th planar layer of a uniform stack (the middle one of each run of
    `every`) and how many layers each stands for: a coarse stack for ranking orientations
    by cost, sliced at a fraction of the exact stack's sections. ([], 0) for a sliver.

    Raises:
        PlanError: bad settings, or `every` below 1.
    """
    if every < 1:
        raise PlanError(f"layers sampled every {every!r}: must be at least 1")
    slicer, low, high = _along_build_direction(subpart, settings)
    if high - low < settings.bounds[0]:
        return [], 0.0
    bounds = planar_bounds(subpart.shape, slicer, low, high,
                           LayerSettings(mode="uniform", thickness=settings.thickness))
    picked = bounds[every // 2::every] or [bounds[len(bounds) // 2]]
    quick = PolyhedronSlicer.of(subpart.shape, slicer.frame)
    if quick is not None:
        return polyhedral_layers(subpart.index, slicer, quick, picked), len(bounds) / len(picked)
    return planar_layers(subpart.index, slicer, picked, settings.workers), len(bounds) / len(picked)
