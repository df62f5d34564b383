"""A decomposition from settings values: the call the `decompose` command and the GUI's
Decomposition object share (settings/decompose.py defines and checks the values)."""
from __future__ import annotations

import math
from typing import Any, Mapping

from freecad_conformal.settings.decompose import DECOMPOSE_SETTINGS
from freecad_conformal.settings.schema import validate


def decompose_with(shape, values: Mapping[str, Any]):
    """The BuildPlan of `shape` with checked settings (SettingError names a bad one), its
    overlapping solids fused first as the plan job fuses them (`solids.united_overlaps`),
    and its closed cavities named as the plan job names them."""
    from freecad_conformal.decomposition.decompose import decompose
    from freecad_conformal.geometry.solids import cavities_note, solids_of, united_overlaps

    v = validate(DECOMPOSE_SETTINGS, values)
    shape, fused = united_overlaps(shape)
    plan = decompose(shape, overhang_angle=math.radians(v["overhang"]), tool=v["tool"],
                     method=v["method"], max_subparts=v["max_subparts"],
                     root_direction=v["root"], check_collisions=v["collision"],
                     thorough=v["root_search"] == "thorough")
    plan.notes[:0] = [note for note in (fused, cavities_note(solids_of(shape))) if note]
    return plan
