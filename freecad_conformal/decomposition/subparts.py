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
        name: a short label ("P1", ...).
        rule: what made this sub-part: "root", "axis-face" (a splitting face meeting the
            centroidal-axis criteria), "concave-face", "area-jump", "branch" (a round member
            cut off square to its axis, decomposition/cuts.branch_candidates), "flange" (a
            flange's side cut off along the shaft under it, cuts.flange_candidates) or "member" (one
            of several members leaving its parent along the same direction,
            decomposition/members.py).
        solid_index: which solid of the input it comes from (compounds give a forest).
        overhang_faces: names ("Face3") of the sub-part's faces that still overhang.
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
    rule: str = "root"
    solid_index: int = 0
    overhang_faces: list[str] = field(default_factory=list)

    def to_dict(self) -> dict:
        """JSON form (shapes are written separately, one STEP per sub-part)."""
        base = None
        if self.base_face is not None:
            centre = self.base_face.CenterOfMass
            base = {"area": float(self.base_face.Area), "centre": [centre.x, centre.y, centre.z]}
        return {"index": self.index, "name": self.name, "parent": self.parent,
                "volume": self.volume, "build_direction": _floats(self.build_direction),
                "rotation_axis": _floats(self.rotation_axis),
                "rotation_angle_deg": float(np.degrees(self.rotation_angle)),
                "overhang_area": self.overhang_area, "overhang_faces": list(self.overhang_faces),
                "base_face": base, "rule": self.rule, "solid": self.solid_index}


#: `BuildPlan.support_reason` of a part built whole because no decomposition could be made.
WHOLE_AFTER_FAILURE = "built whole, as no decomposition could be made (see the notes)"
#: `BuildPlan.support_reason` of a part built whole because the machine builds along +Z only.
WHOLE_ON_MACHINE = "built whole, as the machine cannot tilt the tool"


@dataclass
class BuildPlan:
    """Sub-parts and the order to build them in (indices into `subparts`)."""

    subparts: list[SubPart]
    order: list[int]
    support_area_single_direction: float = 0.0
    notes: list[str] = field(default_factory=list)
    overhang_angle: float = float(np.radians(45.0))
    method: str = "true-direction"
    #: the best single build direction for the whole part (the reference for the saving)
    single_direction: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    #: the centroidal axis of each solid (AxisGraph), for preview and the slicer
    axes: list = field(default_factory=list, repr=False)
    #: why overhang is left, where it is not that no cut saves enough (cuts undone because
    #: the tool would hit the part building them; a decomposition that could not be built)
    support_reason: str | None = None

    @property
    def support_area(self) -> float:
        return float(sum(s.overhang_area for s in self.subparts))

    @property
    def support_area_saved(self) -> float:
        return self.support_area_single_direction - self.support_area

    def ordered(self) -> list[SubPart]:
        return [self.subparts[i] for i in self.order]

    def children(self, index: int) -> list[int]:
        return [s.index for s in self.subparts if s.parent == index]

    def to_dict(self, with_axis: bool = True) -> dict:
        """The JSON form of the plan ("conformal.plan/1")."""
        data = {
            "format": "conformal.plan/1",
            "method": self.method,
            "overhang_angle_deg": float(np.degrees(self.overhang_angle)),
            "order": list(self.order),
            "subparts": [s.to_dict() for s in self.subparts],
            "support_area": self.support_area,
            "single_direction": _floats(self.single_direction),
            "support_area_single_direction": self.support_area_single_direction,
            "support_area_saved": self.support_area_saved,
            "notes": list(self.notes),
        }
        if with_axis:
            data["axes"] = [axis.to_dict() for axis in self.axes]
        return data


def _floats(vector) -> list[float]:
    return [float(c) for c in np.asarray(vector, dtype=float).reshape(-1)]
