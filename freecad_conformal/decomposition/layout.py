"""Separate solids laid out on the platform, each standing on the base of its root.

A part of several solids (an assembly, such as CrankArm's arm and the pin through its bore)
is several objects on one platform. The decomposition plans each solid as a tree of its own,
its root built from the solid's lowest level along the root's direction, and `root="auto"`
may choose a direction other than +Z for a solid. On the machine every root must stand on
the platform: `lay_out` turns each solid about its own centre so its root direction points
up (+Z), lowers it to the level of the others (the lowest root built along +Z as placed,
else the part's lowest point) and sets each solid that had to move beside the others along
+X, `gap` apart, so the tool building one never brushes another. A solid already standing
along +Z, clear of the others, keeps its place across. Then the whole arrangement is set on
the platform itself, the plane z = `PLATFORM_Z` of the machine's part frame (a 3-axis bed, a
trunnion's or a C table's part zero): a part modelled anywhere else in Z (CrankArm at
z = -149, a part centred on its origin) would otherwise be built in the air or below the
table. A part of one solid whose root is built along +Z from the platform stays as placed.
"""
from __future__ import annotations

import copy
import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry.sections import lowest_along
from freecad_conformal.geometry.rotation import rodrigues_matrix, rotation_to
from freecad_conformal.geometry.solids import moved_rigidly
from freecad_conformal.decomposition.subparts import BuildPlan
from freecad_conformal.tolerances import ZERO_LENGTH

UP = np.array([0.0, 0.0, 1.0])

#: A solid whose lowest point is within this (mm) of the platform stands on it.
ON_PLATFORM = 1e-6

#: Height (mm) of the platform's top in the machine's part frame, where the G-code's Z0 is:
#: the bed of a 3-axis machine (its Z travel starts there), the part zero where a
#: trunnion's or a table's rotary axes meet (machines/*.json). Parts are built up from it.
PLATFORM_Z = 0.0

#: Sub-parts reaching further than this (mm) below their root's base are noted: the
#: decomposition does not treat the platform as an obstacle.
BELOW_PLATFORM = 1e-3


@dataclass
class SolidMove:
    """Solid `solid_index` turned by `angle` (rad) about `axis` through `pivot`, then shifted."""

    solid_index: int
    axis: np.ndarray
    angle: float
    pivot: np.ndarray
    shift: np.ndarray

    def apply(self, point: np.ndarray) -> np.ndarray:
        return self.rotate(np.asarray(point, dtype=float) - self.pivot) + self.pivot + self.shift

    def rotate(self, vector: np.ndarray) -> np.ndarray:
        """A vector (or rows of vectors) turned by the move's rotation."""
        return np.asarray(vector, dtype=float) @ rodrigues_matrix(self.axis, self.angle).T

    def shape(self, shape):
        """A moved copy of a FreeCAD shape."""
        App, _ = import_freecad()
        if self.angle > 0.0:
            moved = shape.copy()
            moved.rotate(App.Vector(*self.pivot), App.Vector(*self.axis), math.degrees(self.angle))
            moved.translate(App.Vector(*self.shift))
        else:
            # Only a new location: the same faces and their meshes (a copy of the screw's
            # geometry, set down on the platform, was meshed again to be sliced).
            moved = shape.translated(App.Vector(*self.shift))
        moved_rigidly(shape, moved)
        return moved

    def describe(self) -> str:
        shift = ", ".join(f"{c:+.3f}" for c in self.shift)
        turn = ""
        if self.angle > 0.0:
            axis = ", ".join(f"{c:+g}" for c in np.round(self.axis, 6))
            turn = f"turned {math.degrees(self.angle):.0f} deg about ({axis}) through its centre, "
        return (f"solid {self.solid_index + 1} laid out on the platform: {turn}moved by "
                f"({shift}) mm; its G-code is in that frame")


def lay_out(plan: BuildPlan, gap: float) -> BuildPlan:
    """The plan with every solid standing on the platform along +Z (see the module
    docstring); the same plan when nothing has to move. Notes say what moved."""
    roots = {sub.solid_index: sub for sub in plan.subparts if sub.parent is None}
    if len(roots) == 1 and _upright(next(iter(roots.values()))):
        (k, root), = roots.items()
        lift = PLATFORM_Z - lowest_along(root.shape, UP)
        if abs(lift) <= ON_PLATFORM:
            return plan
        return _moved(plan, {k: SolidMove(k, UP.copy(), 0.0, np.zeros(3), np.array([0.0, 0.0, lift]))})
    shapes = {k: [s.shape for s in plan.subparts if s.solid_index == k] for k in roots}
    # The platform: under the lowest root built along +Z as placed (else the part's bottom).
    upright = [lowest_along(root.shape, UP) for root in roots.values() if _upright(root)]
    platform = min(upright) if upright else lowest_along(_compound([s.shape for s in plan.subparts]), UP)
    moves: dict[int, SolidMove] = {}
    boxes: dict[int, tuple[float, float, float, float]] = {}
    notes: list[str] = []
    for k, root in sorted(roots.items()):
        axis, angle = rotation_to(root.build_direction, UP)
        whole = _compound(shapes[k])
        # The box of a fresh copy: `BoundBox` is read from a triangulation when the shape
        # has one, so a solid the decomposition had meshed turned about another centre
        # than the same solid fresh (the connecting rod's: 1.3 mm apart), and one build of
        # one solid landed in two places.
        box = whole.copy().BoundBox
        pivot = np.array([box.Center.x, box.Center.y, box.Center.z])
        move = SolidMove(k, axis, float(angle), pivot, np.zeros(3))
        turned = move.shape(whole)
        # The root's base goes on the platform: the layers start there.
        # A solid of one sub-part is its root: its bottom is the base (one query, not two).
        base = lowest_along(turned if len(shapes[k]) == 1 else move.shape(root.shape), UP)
        move.shift[2] = platform - base
        below = 0.0 if len(shapes[k]) == 1 else base - lowest_along(turned, UP)
        if below > BELOW_PLATFORM:
            notes.append(f"solid {k + 1}: sub-parts built after its root reach {below:.3f} mm "
                         "below the root's base, into the platform")
        moves[k] = move
        boxes[k] = _footprint(turned, move.shift)
    # Solids built along +Z as modelled, clear of each other, keep their place over the
    # platform (one modelled higher only comes down: two boxes side by side, one 20 mm up,
    # were set apart although nothing was in the way); each other one is set beside those
    # placed, on the side its sub-parts and theirs do not point to (a tool building
    # sideways, and its approach, then face away from the others).
    directions = {k: np.array([m.rotate(np.asarray(s.build_direction, dtype=float))
                               for s in plan.subparts if s.solid_index == k]) for k, m in moves.items()}
    placed: dict[int, tuple[float, float, float, float]] = {}
    for k in sorted(moves):
        move = moves[k]
        upright = move.angle == 0.0
        if not (upright and not any(_overlap(boxes[k], other, gap) for other in placed.values())):
            if placed:
                shift = _beside(boxes[k], placed, directions, k, gap)
                move.shift[:2] += shift
                boxes[k] = (boxes[k][0] + shift[0], boxes[k][1] + shift[0],
                            boxes[k][2] + shift[1], boxes[k][3] + shift[1])
        placed[k] = boxes[k]
    # The arrangement, standing on its own level, onto the platform.
    for move in moves.values():
        move.shift[2] += PLATFORM_Z - platform
    moving = {k: m for k, m in moves.items() if m.angle > 0.0 or np.linalg.norm(m.shift) > ON_PLATFORM}
    if not moving:
        return plan
    laid = _moved(plan, moving)
    laid.notes.extend(notes)
    return laid


def shifted(plan: BuildPlan, offset, why: str) -> BuildPlan:
    """A copy of the plan with every solid moved by `offset` (x, y) mm, in one note that
    says `why`."""
    shift = np.array([float(offset[0]), float(offset[1]), 0.0])
    moves = {k: SolidMove(k, UP.copy(), 0.0, np.zeros(3), shift.copy())
             for k in sorted({sub.solid_index for sub in plan.subparts})}
    text = ", ".join(f"{c:+.3f}" for c in shift)
    return _moved(plan, moves, [f"the plan moved by ({text}) mm over the platform's centre: "
                                f"{why}; its G-code is in that frame"])


def turned_about_vertical(plan: BuildPlan, angle: float, pivot, shift, why: str) -> BuildPlan:
    """A copy of the plan with every solid turned by `angle` (rad, > 0) about the vertical
    through `pivot` (x, y) and then moved by `shift` (x, y) mm, in one note that says `why`."""
    centre = np.array([float(pivot[0]), float(pivot[1]), 0.0])
    move = np.array([float(shift[0]), float(shift[1]), 0.0])
    moves = {k: SolidMove(k, UP.copy(), float(angle), centre.copy(), move.copy())
             for k in sorted({sub.solid_index for sub in plan.subparts})}
    text = ", ".join(f"{c:+.3f}" for c in move)
    return _moved(plan, moves, [f"the plan turned by {math.degrees(angle):.0f} deg about the "
                                f"vertical through ({centre[0]:+.3f}, {centre[1]:+.3f}) and "
                                f"moved by ({text}) mm: {why}; its G-code is in that frame"])


#: Sides a solid may be set beside the others: +X, −X, +Y, −Y (the first wins a tie).
SIDES = (np.array([1.0, 0.0]), np.array([-1.0, 0.0]), np.array([0.0, 1.0]), np.array([0.0, -1.0]))


def _beside(box, placed: dict, directions: dict, k: int, gap: float) -> np.ndarray:
    """(dx, dy) setting footprint `box` `gap` beyond the placed ones, centred on them across,
    on the side least faced by its build directions (towards them) and theirs (towards it)."""
    others = list(placed.values())
    union = (min(b[0] for b in others), max(b[1] for b in others),
             min(b[2] for b in others), max(b[3] for b in others))

    # The tool stands on the side a sub-part is built towards: building towards the others
    # (its directions against `side`), or they towards it, brings a tool over the other.
    def facing(side: np.ndarray) -> float:
        mine = float(np.max(directions[k][:, :2] @ -side))
        theirs = max(float(np.max(directions[j][:, :2] @ side)) for j in placed)
        return max(mine, 0.0) + max(theirs, 0.0)

    side = min(SIDES, key=facing)
    centre = np.array([0.5 * (box[0] + box[1]), 0.5 * (box[2] + box[3])])
    target = np.array([0.5 * (union[0] + union[1]), 0.5 * (union[2] + union[3])])
    half = np.array([0.5 * (box[1] - box[0]), 0.5 * (box[3] - box[2])])
    reach = np.array([0.5 * (union[1] - union[0]), 0.5 * (union[3] - union[2])])
    along = int(np.argmax(np.abs(side)))
    target[along] += side[along] * (reach[along] + gap + half[along])
    return target - centre


def _upright(root) -> bool:
    return bool(np.allclose(root.build_direction, UP, atol=ZERO_LENGTH))


def _moved(plan: BuildPlan, moves: dict[int, SolidMove],
           said: list[str] | None = None) -> BuildPlan:
    """A copy of the plan with the moved solids' sub-parts, bases, directions and axes, and
    `said` added to its notes (default: each move described)."""
    subparts = []
    for sub in plan.subparts:
        move = moves.get(sub.solid_index)
        if move is None:
            subparts.append(sub)
            continue
        direction = move.rotate(np.asarray(sub.build_direction, dtype=float))
        axis, angle = rotation_to(direction, UP)
        subparts.append(dataclasses.replace(
            sub, shape=move.shape(sub.shape), build_direction=direction,
            base_face=None if sub.base_face is None else move.shape(sub.base_face),
            rotation_axis=axis, rotation_angle=float(angle)))
    return dataclasses.replace(plan, subparts=subparts,
                               axes=[_moved_axis(axis, moves.get(k)) for k, axis in enumerate(plan.axes)],
                               notes=list(plan.notes) + (said if said is not None else
                                                         [moves[k].describe() for k in sorted(moves)]))


def _moved_axis(axis, move: SolidMove | None):
    if move is None:
        return axis
    moved = copy.deepcopy(axis)
    for node in moved.nodes:
        node.point = move.apply(node.point)
    for branch in moved.branches:
        branch.direction = move.rotate(branch.direction)
    return moved


def _compound(shapes: list):
    _, Part = import_freecad()
    return shapes[0] if len(shapes) == 1 else Part.Compound(shapes)


def _footprint(shape, shift: np.ndarray) -> tuple[float, float, float, float]:
    """(x_min, x_max, y_min, y_max) of the shape's box, shifted."""
    box = shape.BoundBox
    return (box.XMin + shift[0], box.XMax + shift[0], box.YMin + shift[1], box.YMax + shift[1])


def _overlap(a, b, gap: float) -> bool:
    """Whether two footprints come closer than `gap`."""
    return (a[0] < b[1] + gap and b[0] < a[1] + gap and a[2] < b[3] + gap and b[2] < a[3] + gap)
