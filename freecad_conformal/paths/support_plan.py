"""Which sub-parts get the support `paths/support.py` finds, and where it is left out.

Support is an obstacle until it is broken away, and the build order's collision check
(`decomposition/build_order.py`) knew only the sub-parts: a sub-part's support is left out,
with a note, where it would stand in a sub-part built before it or beside it, or where the
tool building a later sub-part would meet it (sampled as that check samples sub-parts).
"""
from __future__ import annotations

from typing import Sequence

import numpy as np
import shapely

from freecad_conformal.decomposition.subparts import BuildPlan
from freecad_conformal.layers.model import Layer, base_level
from freecad_conformal.paths.support import (StackSupport, SupportSettings, stack_support,
                                             supportable)


def supports_of(plan: BuildPlan, layers: dict[int, list[Layer]], settings: SupportSettings,
                width: float, envelope) -> tuple[dict[int, StackSupport], list[str]]:
    """Each sub-part's support (`paths.support`; none where support is off), and notes on
    what was left out: columns that would stand on nothing known, and the support of a
    sub-part that would stand in another sub-part built before it or beside it, or that
    the tool building a later one would meet (support is an obstacle until it is broken
    away: the build order's collision check knew only the sub-parts)."""
    from freecad_conformal.geometry.collision import sample_spacing

    if not settings.enabled:
        return {}, []
    found: dict[int, StackSupport] = {}
    notes: list[str] = []
    for sub in plan.ordered():
        stack = layers.get(sub.index) or []
        if not stack:
            continue
        if not supportable(stack):
            if sub.overhang_area > 0:
                notes.append(f"sub-part {sub.index}: no support in its 3-D layers (tilted "
                             "layers take no columns)")
            continue
        support = stack_support(stack, settings, width, on_platform=sub.parent is None)
        if support.bridged_area > 0:
            notes.append(f"sub-part {sub.index}: {support.bridged_area:.1f} mm2 of overhang "
                         "laid as bridges from wall to wall, without support, as PrusaSlicer "
                         "does (--support-bridges supports them)")
        if support.dropped_area > 0:
            notes.append(f"sub-part {sub.index}: {support.dropped_area:.1f} mm2 of overhang "
                         "left without support: its columns would stand below the sub-part's "
                         "base, beside its parent")
        if support.empty:
            if support.bridged_area > 0:
                found[sub.index] = support      # no columns; what it bridged is counted
            continue
        samples = support_samples(layers[sub.index], support, sample_spacing(envelope))
        occupied = _support_inside(plan, layers, sub, samples)
        if occupied is not None:
            notes.append(f"sub-part {sub.index}: its support is not printed: it would stand "
                         f"in sub-part {occupied}, built before it or beside it")
            continue
        blocker = _support_blocked_by(plan, layers, sub, samples, envelope)
        if blocker is not None:
            notes.append(f"sub-part {sub.index}: its support is not printed: the tool "
                         f"building sub-part {blocker} later would meet it")
            continue
        found[sub.index] = support
    return found, notes


def _support_inside(plan: BuildPlan, layers: dict[int, list[Layer]], sub,
                    samples: np.ndarray) -> int | None:
    """Another sub-part, built before `sub` or layer by layer with it, that holds some of
    `sub`'s support samples (its columns would be printed into it), else None."""
    from freecad_conformal.geometry.collision import concurrent
    from freecad_conformal.geometry.inside import inside_test

    if not len(samples):
        return None
    order = [s.index for s in plan.ordered()]
    stack = layers[sub.index]
    low, high = samples.min(axis=0), samples.max(axis=0)
    for other in plan.ordered():
        if other.index == sub.index or not layers.get(other.index):
            continue
        after = order.index(other.index) > order.index(sub.index)
        if after and not concurrent(sub.build_direction, base_level(stack), other.build_direction,
                                    base_level(layers[other.index])):
            continue        # a later sub-part's tool: `_support_blocked_by`
        box = other.shape.BoundBox
        if (box.XMin > high[0] or box.XMax < low[0] or box.YMin > high[1] or box.YMax < low[1]
                or box.ZMin > high[2] or box.ZMax < low[2]):
            continue
        if inside_test(other.shape)(samples, False).any():
            return other.index
    return None


def _support_blocked_by(plan: BuildPlan, layers: dict[int, list[Layer]], sub,
                        obstacle: np.ndarray, envelope) -> int | None:
    """A sub-part built after `sub`, not layer by layer with it, whose tool would meet
    `sub`'s support (`obstacle`: its samples, as the collision check samples), else None."""
    from freecad_conformal.geometry.collision import (builds_into, concurrent, sample_spacing,
                                                      surface_points)

    order = [s.index for s in plan.ordered()]
    later = [s for s in plan.ordered()[order.index(sub.index) + 1:] if layers.get(s.index)]
    if not later:
        return None
    spacing = sample_spacing(envelope)
    stack = layers[sub.index]
    for other in later:
        if concurrent(sub.build_direction, base_level(stack), other.build_direction,
                      base_level(layers[other.index])):
            continue
        if builds_into(surface_points(other.shape, spacing), other.build_direction, envelope,
                       obstacle):
            return other.index
    return None


def support_samples(stack: Sequence[Layer], support: StackSupport, spacing: float) -> np.ndarray:
    """Points (N, 3) of a stack's support, on layers about `spacing` apart: on its outlines
    at most `spacing` apart and inside on a grid of that pitch (the collision check's
    sampling; a block standing inside a column's outline must be seen too)."""
    stride = max(1, int(spacing / max(stack[0].thickness, 1e-9)))
    points = [np.zeros((0, 3))]
    for i, layer in enumerate(stack):
        area = support.base[i].union(support.interface[i])
        if area.is_empty or (i % stride and i != len(stack) - 1):
            continue
        rings = shapely.get_coordinates(shapely.segmentize(area.boundary, spacing))
        x0, y0, x1, y1 = area.bounds
        u, v = np.meshgrid(np.arange(x0, x1, spacing), np.arange(y0, y1, spacing))
        grid = np.column_stack((u.ravel(), v.ravel()))
        grid = grid[shapely.contains_xy(area, grid[:, 0], grid[:, 1])]
        found = np.vstack((rings, grid))
        if len(found):
            points.append(layer.to_3d(found))
    return np.vstack(points)
