"""The contract between decomposition and layer planning: sub-parts and their build order.

Decomposition fills a `BuildPlan`; layer and path planning read it. A part that needs no
split is a plan with one sub-part whose build direction is +Z.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class SubPart:
    """One support-free piece of the part, built in its own direction.

    Attributes:
        index: position in `BuildPlan.subparts` (stable id).
        shape: the exact sub-solid (Part.Solid), in the part's frame.
        build_direction: unit vector, pointing away from the parent (layers stack along it).
        base_face: the planar face it is built on (Part.Face), None for the root on the bed.
        parent: index of the sub-part it rests on, None for the root.
        volume: exact volume in mm³.
        rotation_axis, rotation_angle: the rotation (Rodrigues) that brings `build_direction`
            to the machine's build axis +Z, angle in radians.
        overhang_area: area (mm²) of faces still overhanging beyond the allowed angle when
            built in `build_direction`, base excluded.
    """

    index: int
    shape: object = field(repr=False)
    build_direction: np.ndarray
    base_face: object | None = field(default=None, repr=False)
    parent: int | None = None
    volume: float = 0.0
    rotation_axis: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    rotation_angle: float = 0.0
    overhang_area: float = 0.0
    name: str = ""


@dataclass
class BuildPlan:
    """Sub-parts and the order to build them in (indices into `subparts`)."""

    subparts: list[SubPart]
    order: list[int]
    support_area_single_direction: float = 0.0
    notes: list[str] = field(default_factory=list)

    @property
    def support_area(self) -> float:
        return float(sum(s.overhang_area for s in self.subparts))

    @property
    def support_area_saved(self) -> float:
        return self.support_area_single_direction - self.support_area

    def ordered(self) -> list[SubPart]:
        return [self.subparts[i] for i in self.order]
