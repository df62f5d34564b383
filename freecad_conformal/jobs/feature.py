"""One conformal feature on one face from settings values: the call the `feature` command
and the GUI's Feature object share (settings/feature.py defines and checks the values)."""
from __future__ import annotations

from types import SimpleNamespace
from typing import Any, Mapping

from freecad_conformal.errors import PlanError
from freecad_conformal.settings.feature import FEATURE_SETTINGS, KINDS
from freecad_conformal.settings.schema import validate


def plan_feature(face, kind: str, values: Mapping[str, Any], what: str = "", part=None):
    """The toolpath of a `kind` feature on `face`; values are checked first (SettingError
    names the bad one), then the planner for the kind and the face's geometry runs. Every
    move is checked against `part` (the solid the face belongs to; the face alone if None)."""
    from freecad_conformal.paths.features import planners

    if kind not in KINDS:
        raise PlanError(f"feature kind must be one of {', '.join(KINDS)}, got {kind!r}")
    settings = SimpleNamespace(**validate(FEATURE_SETTINGS, values))
    planner = {"rods": planners.plan_rods, "shell": planners.plan_shell,
               "pattern": planners.plan_pattern, "channels": planners.plan_channels,
               "texture": planners.plan_texture}[kind]
    return planner(settings, face, what or kind, part=part)


def plan_features(part, features, what: str = "features", collision_rule: str = "envelope"):
    """One program for several features of `part`: (face, kind, values, name) each, in
    order, tool changes where the tool changes, every move checked (planners.plan_sequence)."""
    from freecad_conformal.paths.features import planners

    items = []
    for face, kind, values, name in features:
        if kind not in KINDS:
            raise PlanError(f"{name}: feature kind must be one of {', '.join(KINDS)}, got {kind!r}")
        items.append((SimpleNamespace(**validate(FEATURE_SETTINGS, values)), face, kind, name))
    return planners.plan_sequence(items, part, what, collision_rule)
