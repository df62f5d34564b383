"""Textures stamped by a masked tool (METHODS section 1: a mask on the tip cures its shape).

Stamps sit on a grid `pitch` apart over an `extent` × `extent` square about the centre, or
`pitch` apart along a curve (the pattern plane's x axis through the centre, mapped onto the
face: a u iso-curve on a cylinder, a great circle on a sphere). The plane is mapped onto the
face as for patterns (patterns.FaceMapping), so the pitch is measured on the surface.

Each stamp's thickness t comes from
- `travel`: the tool starts on the face with the light on and moves t out along the
  normal (the shape grows with the tool, as a rod does) at the tool's stamping feed;
- `dwell`: the tool stands t off the face and the light stays on for the time whose
  exposure cures t deep: t = Dp·ln(E/Ec), E = P·time/A (A the mask's area), so
  time = Ec·exp(t/Dp)·A/P, with Dp and Ec from the tool's settings for the resin.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from freecad_conformal.errors import PlanError
from freecad_conformal.geometry.faces import normals_at, points_at
from freecad_conformal.paths.features.patterns import FaceMapping
from freecad_conformal.process.tools import Mask, Tool
from freecad_conformal.tolerances import ROUNDING_SLACK

#: mJ/cm² → J/mm² (1 mJ = 1e-3 J, 1 cm² = 100 mm²).
_MJ_PER_CM2_TO_J_PER_MM2 = 1e-5
STAMP_MODES = ("travel", "dwell")
LAYOUTS = ("grid", "curve")


def mask_area(mask: Mask) -> float:
    """Area (mm²) of the mask's shape of outer size `size`."""
    s = mask.size
    if mask.shape == "disk":
        return math.pi * s * s / 4.0
    if mask.shape == "square":
        return s * s
    outline = np.asarray(mask_outline(mask))
    x, y = outline[:, 0], outline[:, 1]
    return 0.5 * abs(float(np.dot(x, np.roll(y, 1)) - np.dot(y, np.roll(x, 1))))


def mask_outline(mask: Mask, samples: int = 64) -> list[tuple[float, float]]:
    """The mask's outline (mm, centred) for previews and areas."""
    r = mask.size / 2.0
    if mask.shape == "custom":
        return list(mask.outline)
    if mask.shape == "disk":
        t = np.linspace(0, 2 * math.pi, samples, endpoint=False)
        return list(zip(r * np.cos(t), r * np.sin(t)))
    if mask.shape == "square":
        return [(-r, -r), (r, -r), (r, r), (-r, r)]
    if mask.shape == "star":        # five points, inner radius 0.382 R (a regular star)
        t = math.pi / 2 + np.arange(10) * math.pi / 5
        radii = np.where(np.arange(10) % 2 == 0, r, 0.382 * r)
        return list(zip(radii * np.cos(t), radii * np.sin(t)))
    # heart: the classic parametric curve scaled to the size
    t = np.linspace(0, 2 * math.pi, samples, endpoint=False)
    x = 16 * np.sin(t) ** 3
    y = 13 * np.cos(t) - 5 * np.cos(2 * t) - 2 * np.cos(3 * t) - np.cos(4 * t)
    scale = mask.size / max(np.ptp(x), np.ptp(y))
    return list(zip(scale * x, scale * (y - 0.5 * (y.max() + y.min()))))


def stamp_plane_points(layout: str, pitch: float, extent: float) -> np.ndarray:
    """Stamp centres (N, 2) in the pattern plane about the origin."""
    if layout not in LAYOUTS:
        raise PlanError(f"texture: layout must be one of {', '.join(LAYOUTS)}, got {layout!r}")
    if not (pitch > 0 and extent > 0):
        raise PlanError(f"texture: pitch and extent must be > 0 mm (got {pitch!r}, {extent!r})")
    count = int(math.floor(extent / pitch + ROUNDING_SLACK)) + 1
    line = (np.arange(count) - (count - 1) / 2.0) * pitch
    if layout == "curve":
        return np.column_stack((line, np.zeros(count)))
    xx, yy = np.meshgrid(line, line, indexing="ij")
    # boustrophedon rows: short travels
    xx[1::2] = xx[1::2, ::-1]
    return np.column_stack((xx.ravel(), yy.ravel()))


@dataclass
class Stamps:
    points: np.ndarray      # (N, 3) on the face
    normals: np.ndarray     # (N, 3)


def stamp_positions(face, centre: tuple[float, float], layout: str, pitch: float,
                    extent: float, what: str = "texture") -> Stamps:
    """Stamp centres on the face; those off the (trimmed) face are dropped."""
    plane = stamp_plane_points(layout, pitch, extent)
    mapping = FaceMapping(face, centre)
    mapping.check_wrap(extent, extent if layout == "grid" else 0.0, what)
    uv = mapping.to_uv(plane)
    keep = np.array([face.isPartOfDomain(float(u), float(v)) for u, v in uv])
    if not keep.any():
        raise PlanError(f"{what}: no stamp of the {layout} falls on the face")
    return Stamps(points_at(face, uv[keep]), normals_at(face, uv[keep]))


def dwell_seconds(thickness: float, mask: Mask, power: float, dp: float | None,
                  ec: float | None, tool_id: str) -> float:
    """The dwell that cures `thickness` mm under the mask (module docstring)."""
    if not (dp and ec):
        raise PlanError(f"texture: dwell stamping needs the resin's Dp and Ec in {tool_id}'s "
                        "settings (dp, ec_mj_cm2); use --stamp travel or add them")
    exposure = ec * math.exp(thickness / dp) * _MJ_PER_CM2_TO_J_PER_MM2     # J/mm²
    return exposure * mask_area(mask) / power


def masked(tool: Tool, what: str) -> Mask:
    mask = getattr(tool.spec, "mask", None)
    if mask is None:
        raise PlanError(f"{what}: {tool.id} has no mask; a texture needs a masked tool "
                        "(uv_mask_disk, uv_mask_square, uv_mask_star, uv_mask_heart)")
    return mask
