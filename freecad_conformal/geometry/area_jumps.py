"""Area-jump split planes (METHODS section 4): the fallback when no splitting face qualifies.

Sections every `d` mm along ±X, ±Y, ±Z; where the exact section area jumps,
∂ = (S(i+1) − S(i)) / d > 1 (the published rule, on raw areas), a cut between the two
sections is proposed. The cut is restricted, as for splitting faces, to the interior regions
of the plane's section; the decomposition keeps it only if it saves overhang.
"""
from __future__ import annotations

import numpy as np

from freecad_conformal.errors import GeometryError
from freecad_conformal.geometry.sections import PlanarSlicer, extent_along
from freecad_conformal.geometry.splitting_faces import SplitCandidate, interior_regions

#: Sections per axis when `d` is not given (the jump test only needs to see the steps).
DEFAULT_SLICES = 40

#: The published threshold on ∂ (mm² per mm).
JUMP_THRESHOLD = 1.0

AXES = tuple(np.array(v, dtype=float) for v in np.vstack([np.eye(3), -np.eye(3)]))


def _area_profile(shape, axis: np.ndarray, d: float | None) -> tuple[np.ndarray, np.ndarray, float]:
    """Exact section areas along `axis` (one batch of sections): heights, areas, step."""
    low, high = extent_along(shape, axis)
    step = d if d is not None else (high - low) / DEFAULT_SLICES
    if step <= 0:
        return np.zeros(0), np.zeros(0), 0.0
    heights = np.arange(low + step / 2, high, step)
    if len(heights) < 2:
        return heights, np.zeros(len(heights)), step
    try:
        slicer = PlanarSlicer(shape, axis)
    except GeometryError:
        # A piece left by an earlier Boolean that OCC's check rejects: it gets no area-jump
        # planes (its splitting faces are still tried), rather than stopping the plan.
        return np.zeros(0), np.zeros(0), 0.0
    areas = np.array([s.area for s in slicer.sections(list(heights))])
    return heights, areas, step


def _jumps(heights: np.ndarray, areas: np.ndarray, step: float) -> list[tuple[float, float]]:
    if len(heights) < 2:
        return []
    rates = np.diff(areas) / step
    return [(float(heights[i] + step / 2), float(rates[i]))
            for i in np.nonzero(rates > JUMP_THRESHOLD)[0]]


def area_jumps(shape, direction: np.ndarray, d: float | None = None) -> list[tuple[float, float]]:
    """(height between the two sections, ∂) for each jump with ∂ > 1 along `direction`."""
    heights, areas, step = _area_profile(shape, np.asarray(direction, dtype=float), d)
    return _jumps(heights, areas, step)


def area_jump_planes(shape, build_direction: np.ndarray, d: float | None = None,
                     limit: int = 12) -> list[tuple[float, np.ndarray, np.ndarray]]:
    """(∂, point, normal) of the planes of the largest area jumps along ±X, ±Y, ±Z (the
    build direction itself excluded: a cut across it changes nothing), largest first.

    One batch of sections per axis serves both signs: along −X the same areas are read in
    the opposite order, at negated heights.
    """
    jumps = []
    for axis in AXES[:3]:
        if abs(float(axis @ build_direction)) > 1 - 1e-9:
            continue
        heights, areas, step = _area_profile(shape, axis, d)
        jumps.extend((rate, height, axis) for height, rate in _jumps(heights, areas, step))
        jumps.extend((rate, -height, -axis)
                     for height, rate in _jumps(-heights[::-1], areas[::-1], step))
    jumps.sort(key=lambda item: -item[0])
    return [(rate, axis * height, axis) for rate, height, axis in jumps[:limit]]


def plane_candidates(shape, point: np.ndarray, normal: np.ndarray) -> list[SplitCandidate]:
    """The interior regions of one area-jump plane, as cut candidates."""
    return [SplitCandidate(point, normal, region, "area-jump")
            for region in interior_regions(shape, point, normal)]


def area_jump_candidates(shape, build_direction: np.ndarray, d: float | None = None,
                         limit: int = 12) -> list[SplitCandidate]:
    """Interior regions on the planes of the largest area jumps (see `area_jump_planes`)."""
    candidates: list[SplitCandidate] = []
    for _, point, axis in area_jump_planes(shape, build_direction, d, limit):
        candidates.extend(plane_candidates(shape, point, axis))
    return candidates
