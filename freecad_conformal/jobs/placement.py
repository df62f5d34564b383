"""How the part sits on the table: a decomposition every sub-part of which the machine reaches.

The decomposition builds the root on the table along +Z of the part as placed; its other
sub-parts point wherever their faces lead, and a 5-axis machine's tilt is limited (a
trunnion's A ±120°, a head's ±100°), so a plan can need a tool axis the machine cannot
take (the hinge's lugs are built along −Z). A planner may choose how the part sits on the
table: `reachable_plan` tries the part as placed, then turned so each other axis direction
(−Z, ±X, ±Y) points up, decomposes each placement and keeps the first whose sub-parts the
machine reaches all of.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from freecad_conformal.errors import PlanError
from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry.rotation import rodrigues_matrix, rotation_to
from freecad_conformal.geometry.shape_cache import ShapeCache
from freecad_conformal.geometry.solids import moved_rigidly
from freecad_conformal.geometry.overhang import share_overhang_areas
from freecad_conformal.geometry.surface_mesh import share_deflection, share_face_parts
from freecad_conformal.decomposition.subparts import BuildPlan

#: Directions of the part tried as "up", the part as placed first.
UP_CANDIDATES = ((0.0, 0.0, 1.0), (0.0, 0.0, -1.0), (1.0, 0.0, 0.0), (-1.0, 0.0, 0.0),
                 (0.0, 1.0, 0.0), (0.0, -1.0, 0.0))


@dataclass
class Placement:
    """The part's direction `up` that points along the table normal, and the rotation
    (axis, angle in rad, about the origin) that turned the part there."""

    up: np.ndarray
    axis: np.ndarray
    angle: float

    @property
    def turned(self) -> bool:
        return self.angle > 0.0

    def rotate(self, direction) -> np.ndarray:
        """A direction of the part as given, in the frame of the part as placed."""
        d = np.asarray(direction, dtype=float)
        return rodrigues_matrix(self.axis, self.angle) @ d if self.turned else d

    def describe(self) -> str:
        up = ", ".join(f"{c:+g}" for c in np.round(self.up, 6))
        axis = ", ".join(f"{c:+g}" for c in np.round(self.axis, 6))
        return (f"part placed with its ({up}) direction up: turned {math.degrees(self.angle):.0f} deg "
                f"about ({axis}) through the origin; the G-code is in the turned frame")


#: The turned copies made of each part, by shape identity and direction: each candidate plan
#: of a part places it again, and one copy shares its faces' meshes and measures across
#: them (Pump_Nut's whole twin re-meshed 17 faces the decomposition had: 0.14 s). A copy,
#: not the part itself: the plan meshes and measures what it places, and the caller's part
#: keeps none of it. The copy shares the part's curves and surfaces (nothing here changes a
#: shape's geometry in place: turns and moves are locations) and keeps the triangulation the
#: orientation scans made: with its geometry copied too, BRepMesh meshed every B-spline face
#: of the placed fan again (1.6 s of the decomposition's first 1.7 s) for the same mesh.
_TURNED: ShapeCache[dict] = ShapeCache(limit=32, oriented=True)


def turn_up(shape, up) -> tuple[object, Placement]:
    """A copy of `shape` turned so its direction `up` points along +Z (the same copy for the
    same shape and direction: nothing moves a placed shape in place)."""
    App, _ = import_freecad()
    axis, angle = rotation_to(up)

    def turned():
        copy = shape.copy(False, True)
        if angle > 0.0:
            copy.rotate(App.Vector(0, 0, 0), App.Vector(*axis), math.degrees(angle))
        else:
            share_face_parts(shape, copy)
            share_overhang_areas(shape, copy)
        moved_rigidly(shape, copy)
        share_deflection(shape, copy)
        return copy

    return (_TURNED.get_keyed((shape,), tuple(float(c) for c in up), turned),
            Placement(np.asarray(up, dtype=float), axis, float(angle)))


def reachable_plan(shape, decompose: Callable[[object, Placement], BuildPlan],
                   check: Callable[[BuildPlan], None],
                   turning_helps: Callable[[], bool] = lambda: True
                   ) -> tuple[object, BuildPlan, Placement]:
    """(placed shape, plan, placement) of the first placement whose plan passes `check`
    (the machine's reach); the part as placed is kept whenever it passes, so the costly
    decomposition runs again only for a plan the machine cannot build. `decompose(placed,
    placement)` gets the placement to turn any direction it was given for the part as
    modelled (`Placement.rotate`). `turning_helps()`, asked when the part as placed fails:
    False when every placement is bound to give the same plan, which fails the same way
    (its PlanError is raised then, as the part as placed failed). PlanError with every
    placement's reason when none passes."""
    reasons: list[str] = []
    for up in UP_CANDIDATES:
        placed, placement = turn_up(shape, up)
        plan = decompose(placed, placement)
        try:
            check(plan)
        except PlanError as exc:
            if not reasons and not turning_helps():
                raise PlanError(f"{exc} (turning the part on the table would give the same "
                                "plan)") from exc
            reasons.append(f"{_text(up)} up: {exc}")
            continue
        if placement.turned:
            plan.notes.append(placement.describe())
        return placed, plan, placement
    raise PlanError("no placement of the part (each of ±X, ±Y, ±Z up) lets the machine reach "
                    "every sub-part: " + "; ".join(reasons))


def _text(vector) -> str:
    return "(" + ", ".join(f"{c:+g}" for c in vector) + ")"
