"""Bead cross-section models: the area a bead carries per mm and the spacing that fills a slab.

- "rounded" (the default, PrusaSlicer's model): a rectangle with semicircular sides,
  area `(w − h)·h + π·h²/4`, laid at spacing `w − h·(1 − π/4)` so neighbours overlap just
  enough that the slab is filled;
- "rectangular": area `w·h` at spacing `w`.

Either way area / spacing = h: a region filled at the model's spacing gets exactly its
area × layer height, so the two models differ in line count (time), not in material.
"""
from __future__ import annotations

import math

from freecad_conformal.errors import PlanError

BEAD_MODELS = ("rounded", "rectangular")


def _check(width: float, height: float, model: str) -> float:
    if model not in BEAD_MODELS:
        raise PlanError(f"bead model {model!r} is not one of {', '.join(BEAD_MODELS)}")
    if not (math.isfinite(width) and width > 0 and math.isfinite(height) and height > 0):
        raise PlanError(f"bead width and height must be positive, got {width!r} x {height!r} mm")
    # A bead cannot be rounder than a circle: a layer thicker than the width is a circle's worth.
    return min(height, width)


def bead_area(width: float, height: float, model: str = "rounded") -> float:
    """Cross-section (mm²) of a bead of `width` on a layer of `height`."""
    h = _check(width, height, model)
    if model == "rectangular":
        return width * height
    return (width - h) * h + math.pi * h * h / 4.0


def paths_material(paths, width: float, model: str = "rounded") -> float:
    """Material (mm³) of deposit paths: each one's length times its bead's cross-section
    (its own width where it has one, else `width`, on its layer's thickness)."""
    return float(sum(p.length * bead_area(p.width or width, p.thickness, model) for p in paths))


def bead_spacing(width: float, height: float | None, model: str = "rounded") -> float:
    """Centre distance (mm) of neighbouring beads that fills the slab (`width` when the
    height is unknown)."""
    if height is None:
        return width
    h = _check(width, height, model)
    if model == "rectangular":
        return width
    return width - h * (1.0 - math.pi / 4.0)
