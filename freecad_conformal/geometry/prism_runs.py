"""Heights at which a solid's planar sections are translated copies of each other.

Between two heights where nothing but walls parallel to the slicing direction n crosses the
plane (planes containing n, cylinders and extrusions along it, meeting in lines along it),
every section is the same region moved along n: a leg of the table over its 57 mm, the
jack's arms, the straight stretch of CrankArm's pin. Such a run is cut once and its other
sections are that one's faces translated (`PlanarSlicer.sections`), exact as a cut is.

A run is an open interval of heights that no vertex, no other face and no other edge of the
solid reaches (their spans along n from the face cutter's boxes, which contain them), so the
faces the plane crosses and where it crosses their edges stay the same along it.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

from freecad_conformal.geometry.frames import cross
from freecad_conformal.geometry.plane_curves import STRAIGHT_CURVES, curve_name

#: A wall's axis or normal within this (|sin| or |cos|) of being parallel or square to n
#: counts as exactly so: over a 100 mm run the section then moves by 1e-10 mm sideways,
#: a thousand times below OCC's confusion distance.
PARALLEL = 1e-12

#: Surfaces (FreeCAD's names) that are walls along n when their axis or direction is.
_ALONG_AXIS = {"Cylinder": "Axis", "SurfaceOfExtrusion": "Direction"}


def is_wall(surface, n: np.ndarray) -> bool:
    """Whether `surface` is ruled along n: a plane containing n, a cylinder or an extrusion
    along it."""
    kind = type(surface).__name__
    if kind == "Plane":
        return abs(float(np.array(tuple(surface.Axis)) @ n)) < PARALLEL
    attribute = _ALONG_AXIS.get(kind)
    if attribute is None:
        return False
    axis = np.array(tuple(getattr(surface, attribute)))
    return float(np.linalg.norm(cross(axis / np.linalg.norm(axis), n))) < PARALLEL


def is_along(edge, n: np.ndarray) -> bool:
    """Whether `edge` is a straight line along n (where two walls meet)."""
    if curve_name(edge) not in STRAIGHT_CURVES:
        return False
    direction = np.array(tuple(edge.tangentAt(edge.FirstParameter)))
    return float(np.linalg.norm(cross(direction / np.linalg.norm(direction), n))) < PARALLEL


def free_runs(blocked: Sequence[tuple[float, float]]) -> list[tuple[float, float]]:
    """The open gaps between the `blocked` spans (low, high), lowest first."""
    runs: list[tuple[float, float]] = []
    reach = None
    for low, high in sorted(blocked):
        if reach is not None and low > reach:
            runs.append((reach, low))
        reach = high if reach is None else max(reach, high)
    return runs


def copy_sources(runs: Sequence[tuple[float, float]], heights: Sequence[float]) -> list[int]:
    """Per height, the index of the height it is a copy of: the first given in the same run;
    its own index outside every run (and for the first of each run)."""
    sources = list(range(len(heights)))
    first_in: dict[int, int] = {}
    lows = np.array([low for low, _ in runs])
    for index, height in enumerate(heights):
        k = int(np.searchsorted(lows, height)) - 1
        if k < 0 or not runs[k][0] < height < runs[k][1]:
            continue
        sources[index] = first_in.setdefault(k, index)
    return sources
