"""Decomposition of a solid into support-free sub-parts (METHODS sections 3 and 4).

Each piece starts with the overhang it has in its build direction. While some remains, the
candidate cuts are tried exactly (a Boolean split along one planar region): regions on the
planes of faces with concave edges, checked against the centroidal axis' break links
(section 3), then the area-jump planes of section 4. The cut that leaves the least total
overhang wins, the piece beyond it becomes a child built away from its parent along the
plane's normal, and both halves are refined again. A cut that saves nothing is not made,
so a part that is already support-free stays whole, except where several members leave one
face along the build direction (a table's legs): those become sub-parts built on it, as in
section 4's partition (planning/members.py).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from freecad_conformal.errors import GeometryError, PlanError
from freecad_conformal.geometry.concave_edges import concave_edges
from freecad_conformal.geometry.solids import solids_of
from freecad_conformal.geometry.splitting_faces import SplitCandidate, repaired, split_solid
from freecad_conformal.planning.cut_search import CutSearch, best_cut
from freecad_conformal.planning.cuts import (LazyAxis, SavingEstimate, area_jump_candidates,
                                             face_candidates)
from freecad_conformal.planning.rotation import rotation_to
from freecad_conformal.planning.trial import Trial, can_fork, worth_a_trial
from freecad_conformal.planning.subparts import BuildPlan, SubPart
from freecad_conformal.planning.support import (DEFAULT_OVERHANG_ANGLE, best_single_direction,
                                                check_angle, lowest_level, overhang_area,
                                                overhang_report)

METHODS = ("true-direction", "published")

#: `root_direction` value that lets each solid's root be built along the best of ±X, ±Y, ±Z
#: when that leaves less overhang than the part as placed (+Z).
AUTO_ROOT = "auto"

#: Machine build axis: every sub-part is turned so its build direction points along it.
BUILD_AXIS = np.array([0.0, 0.0, 1.0])

#: A cut must save at least this much overhang (mm², and this fraction of what remains) to
#: be worth a new sub-part: below it the split only adds a rotation and a seam.
MIN_SAVING = 1e-3
MIN_SAVING_FRACTION = 1e-4

#: Two directions within this angle (rad) are the same build direction.
SAME_DIRECTION = math.radians(1.0)

#: A piece reaches its base level when its lowest point is within this (mm) of it.
LEVEL_TOLERANCE = 1e-4

#: More sub-parts than this is taken as a runaway split and stops the refinement.
DEFAULT_MAX_SUBPARTS = 24


@dataclass
class _Piece:
    shape: object
    direction: np.ndarray
    base_faces: list = field(default_factory=list)
    solid_index: int = 0
    rule: str = "root"
    overhang: float = 0.0
    #: concave edges of the piece this one was cut from (its own lie on them), None for
    #: an uncut solid
    ancestor_concave: list | None = None
    #: triangulation deflection of the solid's mesh (geometry/surface_mesh.py), the same
    #: for all its pieces so a face a cut left alone keeps its triangulation
    deflection: float | None = None
    _concave: list | None = None
    _report: object = None
    _factor: tuple | None = None

    def concave(self) -> list:
        """The piece's concave edges (measured once)."""
        if self._concave is None:
            self._concave = concave_edges(self.shape, within=self.ancestor_concave)
        return self._concave

    def mesh(self):
        """The piece's mesh, None when it has no closed one."""
        from freecad_conformal.geometry.surface_mesh import surface_mesh

        return surface_mesh(self.shape, self.deflection)


def decompose(shape, *, overhang_angle: float = DEFAULT_OVERHANG_ANGLE, tool: str = "fdm_0p4",
              method: str = "true-direction",
              root_direction: Sequence[float] | str = (0.0, 0.0, 1.0),
              max_subparts: int = DEFAULT_MAX_SUBPARTS, check_collisions: bool = True,
              axis_step: float | None = None) -> BuildPlan:
    """Split `shape` into sub-parts that build without support, and order them.

    Args:
        shape: a solid or a compound of solids, placed as it sits on the bed (+Z up).
        overhang_angle: allowed overhang from the build direction (rad, default 45°).
        tool: id of the tool in the library whose envelope is checked for collisions.
        method: "true-direction" (the axis follows inclined members) or "published"
            (the axis turns to the nearest of ±X, ±Y, ±Z as in METHODS section 3).
        root_direction: build direction of each solid's first sub-part, or "auto": +Z
            unless building the solid's root along its best single axis direction leaves
            less overhang after the split (a note says so).
        max_subparts: stop splitting beyond this many sub-parts (a note says so).
        check_collisions: order brothers so the tool envelope clears what is built.
        axis_step: step of the centroidal axis (mm); default from the part's size.
    Raises:
        GeometryError: the shape is not a valid solid.
        PlanError: bad parameters, or no collision-free order exists.
    """
    check_angle(overhang_angle)
    if method not in METHODS:
        raise PlanError(f"decomposition method must be one of {', '.join(METHODS)}, got {method!r}")
    if max_subparts < 1:
        raise PlanError(f"max_subparts must be at least 1, got {max_subparts}")
    auto = isinstance(root_direction, str)
    if auto and root_direction != AUTO_ROOT:
        raise PlanError(f"root direction must be a 3-vector or {AUTO_ROOT!r}, got {root_direction!r}")
    root = np.array([0.0, 0.0, 1.0]) if auto else np.asarray(root_direction, dtype=float)
    if root.shape != (3,) or not np.all(np.isfinite(root)) or np.linalg.norm(root) < 1e-12:
        raise PlanError(f"root direction must be a non-zero 3-vector, got {list(root_direction)!r}")
    root = root / np.linalg.norm(root)
    solids = solids_of(shape, "part")
    notes: list[str] = []
    pieces: list[_Piece] = []
    parents: list[int | None] = []
    axes = []
    for solid_index, solid in enumerate(solids):
        budget = max_subparts - len(pieces)
        plan = _Planner(solid, solid_index, overhang_angle, method, axis_step, budget)
        trial = None
        try:
            if auto:
                if worth_a_trial(solid) and can_fork():
                    trial = Trial()  # starting up while the direction is found
                # Its mesh first: the overhang in six directions then reads faces from it.
                plan.root_mesh()
                direction, area = best_single_direction(solid, overhang_angle)
                turn = _angle(direction, root) > SAME_DIRECTION
                if (trial is not None and turn
                        and overhang_area(solid, root, overhang_angle) > area + MIN_SAVING):
                    # The as-placed plan may keep more overhang than turning the solid
                    # whole: plan from that direction on the other core meanwhile.
                    trial.plan(plan, direction)
                elif trial is not None:
                    trial.stop()
                    trial = None
            axis, refined = plan(root, notes)
            if auto and _total(refined) > area + MIN_SAVING and turn:
                # The part as placed keeps more overhang than turning it whole would: plan
                # from that direction and keep whichever leaves less.
                trial_notes: list[str] = []
                result = None
                if trial is not None:
                    # Its axis, while the child may still be planning: needed if it wins.
                    other_axis = plan.axis(direction)
                    other_axis.get()
                    result = trial.result(_Piece)
                    trial = None
                if result is not None:
                    other = other_axis, result[0]
                    trial_notes = result[1]
                else:
                    other = plan(direction, trial_notes)
                if _total(other[1]) < _total(refined) - MIN_SAVING:
                    axis, refined = other
                    notes.extend(trial_notes)
                    notes.append(f"solid {solid_index + 1}: root built along "
                                 f"{_text(direction)} (less overhang than as placed)")
        finally:
            if trial is not None:
                trial.stop()
        axes.append(_label(axis, refined))
        first = len(pieces)
        pieces.extend(refined)
        parents.extend(_parents_of(refined, first))
    subparts = [_subpart(i, p, parents[i], overhang_angle) for i, p in enumerate(pieces)]
    from freecad_conformal.planning.build_order import build_order

    order = build_order(subparts, tool=tool if check_collisions else None, notes=notes)
    single = _best_single(solids, overhang_angle)
    return BuildPlan(subparts=subparts, order=order, support_area_single_direction=single[1],
                     notes=notes, overhang_angle=overhang_angle, method=method,
                     single_direction=single[0], axes=axes)


@dataclass
class _Planner:
    """Plans one solid from a given root direction."""

    solid: object
    solid_index: int
    angle: float
    method: str
    axis_step: float | None
    budget: int

    def axis(self, root: np.ndarray) -> LazyAxis:
        """The solid's centroidal axis from `root`, computed when first needed."""
        from freecad_conformal.geometry.centroidal_axis import centroidal_axis

        return LazyAxis(lambda: centroidal_axis(self.solid, method=self.method,
                                                step=self.axis_step, start_direction=root))

    def root_mesh(self):
        """The solid's mesh (geometry/surface_mesh.py), as its pieces' are made."""
        from freecad_conformal.geometry.surface_mesh import mesh_deflection, surface_mesh

        return surface_mesh(self.solid, mesh_deflection(self.solid))

    def __call__(self, root: np.ndarray, notes: list[str]):
        """(axis, refined pieces) from `root`."""
        from freecad_conformal.geometry.surface_mesh import mesh_deflection

        axis = self.axis(root)
        start = _Piece(self.solid, root, [], self.solid_index, "root",
                       deflection=mesh_deflection(self.solid))
        return axis, _refine(start, self.angle, axis, budget=self.budget, notes=notes)

    def pieces(self, root: np.ndarray) -> tuple[list, list[str]]:
        """(refined pieces, notes) from `root` (the trial's form: the axis stays lazy)."""
        notes: list[str] = []
        return self(root, notes)[1], notes


def _label(axis: LazyAxis, pieces: list[_Piece]):
    """The solid's axis; cuts along splitting faces meeting its criteria become "axis-face"."""
    for piece in pieces:
        if piece.rule in ("concave-face", "axis-face"):
            probe = SplitCandidate(np.zeros(3), piece.direction, piece.base_faces[0], piece.rule)
            piece.rule = "axis-face" if axis.supports(probe) else "concave-face"
    return axis.get()


def _total(pieces: list[_Piece]) -> float:
    return float(sum(p.overhang for p in pieces))


def _angle(a: np.ndarray, b: np.ndarray) -> float:
    return math.acos(float(np.clip(np.asarray(a) @ np.asarray(b), -1.0, 1.0)))


def _text(vector) -> str:
    return "(" + ", ".join(f"{float(c):+.3g}" for c in vector) + ")"


def _best_single(solids: list, angle: float) -> tuple[np.ndarray, float]:
    from freecad_conformal.planning.support import best_single_direction
    from freecad_conformal.freecad_env import import_freecad

    _, Part = import_freecad()
    whole = solids[0] if len(solids) == 1 else Part.makeCompound(solids)
    return best_single_direction(whole, angle)


def _subpart(index: int, piece: _Piece, parent: int | None, angle: float) -> SubPart:
    axis, rotation = rotation_to(piece.direction, BUILD_AXIS)
    on_bed = parent is None
    if piece._report is not None and piece._report.angle == angle and on_bed == (piece.rule == "root"):
        report = piece._report  # read while planning, with the same base faces
    else:
        report = overhang_report(piece.shape, piece.direction, angle, piece.base_faces,
                                 on_bed=on_bed)
    base = piece.base_faces[0] if piece.base_faces else _bed_face(piece.shape, piece.direction)
    # Layers and paths cut the sub-part again: it must pass OCC's check.
    return SubPart(index=index, shape=repaired(piece.shape), build_direction=piece.direction,
                   base_face=base, parent=parent, volume=float(piece.shape.Volume),
                   rotation_axis=axis, rotation_angle=rotation, overhang_area=report.area,
                   name=f"P{index + 1}", rule=piece.rule, solid_index=piece.solid_index,
                   overhang_faces=[f"Face{i + 1}" for i, _ in report.faces])


def _bed_face(shape, d: np.ndarray):
    """The largest planar face on the lowest plane facing −d (the face on the bed), if any."""
    from freecad_conformal.planning.support import plane_normal

    low = lowest_level(shape, d)
    best = None
    for face in shape.Faces:
        normal = plane_normal(face)
        if normal is None or normal @ d > -1 + 1e-9:
            continue
        if abs(float(np.array(tuple(face.Vertexes[0].Point)) @ d) - low) > LEVEL_TOLERANCE:
            continue
        if best is None or face.Area > best.Area:
            best = face
    return best


def _overhang(piece: _Piece, angle: float) -> float:
    return _report(piece, angle).area


def _refine(piece: _Piece, angle: float, axis, budget: int, notes: list[str]) -> list[_Piece]:
    """The piece split (recursively) until no cut saves overhang; at most `budget` pieces."""
    report = _report(piece, angle)
    piece.overhang = report.area
    if piece.overhang <= MIN_SAVING or budget <= 1:
        if budget <= 1 and piece.overhang > MIN_SAVING:
            notes.append(f"stopped splitting at the sub-part limit with {piece.overhang:.3f} mm² "
                         "of overhang left")
        return _members(piece, angle, axis, budget, notes)
    search = _search()
    needed = search.needed(piece.overhang)
    estimate = SavingEstimate(piece.shape, angle, report)
    best = best_cut(piece, face_candidates(piece.shape, estimate, needed, piece.concave()),
                    angle, search, axis)
    if best is None:
        # Section 4's area-jump rule only where no splitting face helps: its sections along
        # three axes cost more than everything else here.
        best = best_cut(piece, area_jump_candidates(piece.shape, piece.direction, estimate,
                                                    needed), angle, search)
    if best is None:
        return _members(piece, angle, axis, budget, notes)
    _, keeper, children = best
    result = _refine(keeper, angle, axis, budget - len(children), notes)
    for child in children:
        result.extend(_refine(child, angle, axis, max(budget - len(result), 1), notes))
    return result


def _members(piece: _Piece, angle: float, axis, budget: int, notes: list[str]) -> list[_Piece]:
    """The piece, or its base and the members leaving it (see `planning/members.py`), each
    refined again."""
    from freecad_conformal.planning.members import member_split

    split = member_split(piece, angle, budget, _try_cut) if budget > 2 else None
    if split is None:
        return [piece]
    keeper, children = split
    result = _refine(keeper, angle, axis, budget - len(children), notes)
    for child in children:
        result.extend(_refine(child, angle, axis, max(budget - len(result), 1), notes))
    return result


def _search() -> CutSearch:
    """How `best_cut` reads and cuts pieces (looked up at each call, so a test may count
    the exact cuts)."""
    return CutSearch(try_cut=_try_cut, report=_report, min_saving=MIN_SAVING,
                     min_fraction=MIN_SAVING_FRACTION, level_tolerance=LEVEL_TOLERANCE,
                     same_direction=SAME_DIRECTION)


def _report(piece: _Piece, angle: float):
    """The piece's overhang report (kept: a cut's pieces are read when the cut is tried and
    again when the winner is refined)."""
    if piece._report is None or piece._report.angle != angle:
        # The trial cuts read the piece's mesh; the report reads its faces' parts of it.
        piece.mesh()
        piece._report = overhang_report(piece.shape, piece.direction, angle, piece.base_faces,
                                        on_bed=piece.rule == "root")
    return piece._report


def _try_cut(piece: _Piece, candidate: SplitCandidate, angle: float,
             regions: list | None = None, same_direction: bool = False):
    """(total overhang after the cut, kept piece, children) or None when the cut is no use.

    `regions` (default: the candidate's) are cut at once, each child resting on the regions
    it touches; `same_direction` lets children be built along the piece's own direction
    (members, planning/members.py), which a cut made to save overhang never wants."""
    regions = regions or [candidate.region]
    pieces = split_solid(piece.shape, regions)
    if len(pieces) < 2:
        return None
    d = piece.direction
    low = lowest_level(piece.shape, d)
    on_base = [p for p in pieces if lowest_level(p, d) <= low + LEVEL_TOLERANCE
               and _holds_base(p, piece)]
    if len(on_base) != 1:
        return None
    keeper_shape = on_base[0]
    keeper = _Piece(keeper_shape, d, piece.base_faces, piece.solid_index, piece.rule,
                    ancestor_concave=piece.concave(), deflection=piece.deflection)
    total = _overhang(keeper, angle)
    children = []
    for shape in pieces:
        if shape is keeper_shape:
            continue
        side = (np.array(tuple(shape.CenterOfMass)) - candidate.point) @ candidate.normal
        direction = candidate.normal if side > 0 else -candidate.normal
        if not same_direction and math.acos(float(np.clip(direction @ d, -1, 1))) < SAME_DIRECTION:
            return None
        base = regions if len(regions) == 1 else [r for r in regions if _touch_area(shape, r) > 0]
        if not base:
            return None
        child = _Piece(shape, direction, base, piece.solid_index, candidate.rule,
                       ancestor_concave=piece.concave(), deflection=piece.deflection)
        total += _overhang(child, angle)
        children.append(child)
    return total, keeper, children


def _holds_base(shape, piece: _Piece) -> bool:
    """Whether `shape` carries the piece's base faces (always true for a root on the bed)."""
    if not piece.base_faces:
        return True
    # A shared area implies contact: no distance query needed (distToShape on B-spline
    # pieces cost more than the split itself).
    return any(_touch_area(shape, face) > 0 for face in piece.base_faces)


def _touch_area(shape, region) -> float:
    """Area shared between `region` (a planar face) and the faces of `shape` in its plane."""
    from freecad_conformal.planning.support import plane_normal

    normal = plane_normal(region)
    level = float(np.array(tuple(region.Vertexes[0].Point)) @ normal)
    area = 0.0
    for face in shape.Faces:
        n = plane_normal(face)
        if n is None or abs(abs(n @ normal) - 1) > 1e-9:
            continue
        if abs(float(np.array(tuple(face.Vertexes[0].Point)) @ normal) - level) > LEVEL_TOLERANCE:
            continue
        if face.BoundBox.intersect(region.BoundBox):
            area += float(face.common(region).Area)
    return area


def _parents_of(pieces: list[_Piece], offset: int) -> list[int | None]:
    """Parent of each piece: the other piece sharing most of its base faces (a cut made
    early may end up resting on a piece split off later)."""
    parents: list[int | None] = []
    for index, piece in enumerate(pieces):
        if not piece.base_faces:
            parents.append(None)
            continue
        shares = [(sum(_touch_area(other.shape, f) for f in piece.base_faces), j)
                  for j, other in enumerate(pieces) if j != index]
        area, j = max(shares) if shares else (0.0, None)
        if j is None or area <= 0:
            raise GeometryError(f"sub-part {offset + index + 1} rests on no other sub-part")
        parents.append(offset + j)
    return parents
