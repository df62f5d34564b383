"""Decomposition of a solid into support-free sub-parts (METHODS sections 3 and 4).

Each piece starts with the overhang it has in its build direction. While some remains, the
candidate cuts are tried exactly (a Boolean split along one planar region): regions on the
planes of faces with concave edges, checked against the centroidal axis' break links
(section 3), then the area-jump planes of section 4. The cut that leaves the least total
overhang wins, the piece beyond it becomes a child built away from its parent along the
plane's normal, and both halves are refined again. A cut that saves nothing (or under
2 % of the piece's overhang: planner.MIN_SAVING_FRACTION) is not made, so a part that is
already support-free stays whole, except where several members leave one face along the
build direction (a table's legs): those become sub-parts built on it, as in section 4's
partition (decomposition/members.py).
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

from freecad_conformal.errors import GeometryError, PlanError
from freecad_conformal.geometry.frames import angle_between, vector_text
from freecad_conformal.geometry.occ_binary import to_binary
from freecad_conformal.geometry.solids import solids_of
from freecad_conformal.geometry.splitting_faces import SplitCandidate, repaired
from freecad_conformal.decomposition.cuts import (LazyAxis)
from freecad_conformal.geometry.rotation import rotation_to
from freecad_conformal.decomposition.planner import (LEVEL_TOLERANCE, MIN_SAVING, SAME_DIRECTION,
                                                     Piece, Planner, touch_area)
from freecad_conformal.decomposition.trial import (EarlyTrial, Trial, can_start_child, planned,
                                                   trial_spec, worth_a_trial)
from freecad_conformal.decomposition.subparts import BuildPlan, SubPart
from freecad_conformal.geometry.overhang import (AXIS_DIRECTIONS, CUBE_DIRECTIONS,
                                                DEFAULT_OVERHANG_ANGLE, MIN_BASE_AREA,
                                                base_area, best_single_direction,
                                                check_angle, footprint_area,
                                                lowest_level, orientation_candidates,
                                                overhang_area, overhang_report,
                                                standing_directions, stands)
from freecad_conformal.settings.decompose import METHODS
from freecad_conformal.tolerances import PARALLEL_COS_SLACK, ZERO_LENGTH
#: `root_direction` value that lets each solid's root be built along the best of ±X, ±Y, ±Z
#: (or a further direction: `_turned_further`) when that leaves less overhang than the part
#: as placed (+Z).
AUTO_ROOT = "auto"
#: Machine build axis: every sub-part is turned so its build direction points along it.
BUILD_AXIS = np.array([0.0, 0.0, 1.0])
#: More sub-parts than this is taken as a runaway split and stops the refinement.
DEFAULT_MAX_SUBPARTS = 24
#: Overhang (mm²) a turned root must save against the part as placed to be taken: less is
#: the measure's own noise. A hollow sphere read 919.04 mm² along ±Z and 918.60 along ±Y
#: (exact: 920.15 every way), and was turned onto its side "with less overhang than as
#: placed". The search ties whole plans within the same 1 mm² (jobs/search.OVERHANG_TIE).
TURN_SAVING = 1.0


def decompose(shape, *, overhang_angle: float = DEFAULT_OVERHANG_ANGLE, tool="fdm_0p4",
              method: str = "true-direction",
              root_direction: Sequence[float] | str = (0.0, 0.0, 1.0),
              max_subparts: int = DEFAULT_MAX_SUBPARTS, check_collisions: bool = True,
              axis_step: float | None = None, with_axes: bool = True,
              early: EarlyTrial | None = None, thorough: bool = False,
              whole_when_support_free: bool = False,
              whole_along: dict[int, Sequence[float]] | None = None) -> BuildPlan:
    """Split `shape` into sub-parts that build without support, and order them.

    Args:
        shape: a solid or a compound of solids, placed as it sits on the bed (+Z up).
        overhang_angle: allowed overhang from the build direction (rad, default 45°).
        tool: the tool whose envelope is checked for collisions: its id in the library, or
            the Tool itself (a job passes the one it checked).
        method: "true-direction" (the axis follows inclined members) or "published"
            (the axis turns to the nearest of ±X, ±Y, ±Z as in METHODS section 3).
        root_direction: build direction of each solid's first sub-part, or "auto": +Z
            unless building the solid's root along its best single axis direction, or the
            best of the cube's edges and corners or of its largest faces' on which it
            stands (`_turned_further`), leaves less overhang after the split (a note says
            so).
        max_subparts: stop splitting beyond this many sub-parts (a note says so).
        check_collisions: order brothers so the tool envelope clears what is built.
        axis_step: step of the centroidal axis (mm); default from the part's size.
        with_axes: compute each solid's whole centroidal axis for the plan (`axes`, for
            the preview and the JSON plan) and label the cuts it supports "axis-face".
            The search computes it only where it decides a tie; a job that only builds
            the plan skips the rest (the bottle's: 2.5 s of its 9 s plan choice).
        early: a solid's trial begun before (`trial.EarlyTrial`), used for that solid.
        thorough: with an auto root, also plan each solid turned over (`_turned_further`)
            where its plan keeps overhang: CrankArm's arm keeps 647 mm² that way against
            1,170, at 10 s more (20 s on FreeCAD 1.0).
        whole_when_support_free: with an auto root, a solid that stands support-free as
            placed, or turned whole (`_support_free_whole`), is one sub-part: no members
            split off (METHODS section 4 makes a table's legs sub-parts of their own, all
            built the same way: more sub-parts, no overhang saved). The plan job asks it
            for a part of several solids, as its search builds one solid whole wherever
            that is support-free.
        whole_along: with an auto root, {solid index: direction} of solids built whole along
            that direction (one sub-part each, in the shape's frame): the plan job's search
            chose it among the solid's support-free orientations (`jobs/plan.py`).
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
    if root.shape != (3,) or not np.all(np.isfinite(root)) or np.linalg.norm(root) < ZERO_LENGTH:
        raise PlanError(f"root direction must be a non-zero 3-vector, got {list(root_direction)!r}")
    root = root / np.linalg.norm(root)
    solids = solids_of(shape, "part")
    notes: list[str] = []
    pieces: list[Piece] = []
    parents: list[int | None] = []
    axes = []
    envelope = _envelope(tool) if check_collisions else None
    for solid_index, solid in enumerate(solids):
        budget = max_subparts - len(pieces)
        plan = Planner(solid, solid_index, overhang_angle, method, axis_step, budget,
                       envelope=envelope)
        trial = None
        worth = auto and worth_a_trial(solid)
        # The solid as given, for the plan from the best single direction wherever it is
        # made (a child on the command line, here in FreeCAD's GUI): the plan from the root
        # cuts this very solid, and what OCC's Booleans and the caches keep of it changed
        # CrankArm's plan from there (six sub-parts here, seven in the child). Written before
        # it is meshed here: a mesh sets flags on some edges that binary keeps, and the
        # child meshes it again anyway. A solid not worth a child is planned here
        # everywhere, on the solid itself (sharing its meshes).
        begun = early.take(solid) if worth and early is not None else None
        if begun is not None:
            written, trial = begun
        else:
            written = to_binary(solid) if worth else None
            if worth and can_start_child():
                # Starting up (interpreter, FreeCAD) and meshing the solid while it is
                # meshed here and the direction found: it then plans at once (the fan's
                # child meshed for 1.6 s after the request; CrankArm's arm waited 0.14 s).
                trial = Trial()
                trial.prepare(written)
        try:
            if auto:
                # Its mesh first: the overhang in every candidate direction reads faces
                # from it.
                plan.root_mesh()
                chosen = (whole_along or {}).get(solid_index)
                whole = (_support_free_whole(solid, root, overhang_angle) if chosen is None
                         else np.asarray(chosen, dtype=float))
                as_placed = (chosen is None and whole is None and whole_when_support_free
                             and overhang_area(solid, root, overhang_angle) <= MIN_SAVING
                             and stands(solid, root))
                if as_placed:
                    whole = root
                if whole is not None:
                    # Turned whole it prints without support: one piece beats any split of
                    # the part as placed (a planar slicer would simply turn it over).
                    axis, refined = (plan.whole(whole)
                                     if whole_when_support_free or chosen is not None
                                     else plan(whole, notes))
                    if chosen is None:      # the search's own note names its choice
                        notes.append(f"solid {solid_index + 1}: built whole as placed: it is "
                                     "support-free that way" if as_placed else
                                     f"solid {solid_index + 1}: root built along "
                                     f"{vector_text(whole)}: the whole solid is support-free "
                                     "that way")
                    if with_axes:
                        axes.append(_label(axis, refined))
                    first = len(pieces)
                    pieces.extend(refined)
                    parents.extend(_parents_of(refined, first))
                    continue
            pristine = None
            forced = None
            placed = root
            if auto:
                direction, area = best_single_direction(solid, overhang_angle, AXIS_DIRECTIONS,
                                                        tie=TURN_SAVING)
                if not stands(solid, root):
                    # As placed it rests on a line or a point (a ring on its edge, a foot on
                    # its edge): the part must stand, whatever the overhang it keeps. Its
                    # root is the best direction it stands in, axis or face.
                    standing, _ = best_single_direction(solid, overhang_angle, tie=TURN_SAVING)
                    if stands(solid, standing):
                        forced = (f"solid {solid_index + 1}: root built along {vector_text(standing)}: "
                                  f"as placed it would rest on "
                                  f"{footprint_area(solid, root):.1f} mm² of first layer")
                        root = standing
                turn = angle_between(direction, root) > SAME_DIRECTION
                if (worth and turn
                        and overhang_area(solid, root, overhang_angle) > area + TURN_SAVING):
                    pristine = written
                if trial is not None and pristine is not None:
                    # The as-placed plan may keep more overhang than turning the solid
                    # whole: plan from that direction on the other core meanwhile.
                    trial.plan(plan, direction, pristine)
                elif trial is not None:
                    trial.stop()
                    trial = None
            axis, refined = plan(root, notes)
            placed_total = _total(refined)
            # Said once the root is settled: a further root may still replace this one.
            root_notes: list[str] = [] if forced is None else [forced]
            if auto and placed_total > area + TURN_SAVING and turn:
                # The part as placed keeps more overhang than turning it whole would: plan
                # from that direction and keep whichever leaves less.
                trial_notes: list[str] = []
                other = None
                try:
                    result = None
                    if trial is not None:
                        # Its axis, while the child may still be planning: needed if it wins.
                        other_axis = plan.axis(direction)
                        if with_axes:
                            other_axis.get()
                        result = trial.result()
                        trial = None
                    if result is not None:
                        other = other_axis, result[0]
                        trial_notes = result[1]
                    elif pristine is not None:
                        # As the child plans it (the same steps, the same binary trips):
                        # the same plan, bit for bit, where no child could start (FreeCAD's
                        # GUI starts none).
                        made, made_notes = planned(trial_spec(plan, direction, pristine))
                        other = plan.axis(direction), [Piece.from_data(item) for item in made]
                        trial_notes.extend(made_notes)
                    else:
                        other = plan(direction, trial_notes)
                except GeometryError as exc:
                    # Only an alternative to the plan as placed, which stands: a Boolean
                    # OCC cannot do there (the bottle along X) must not lose the part.
                    notes.append(f"solid {solid_index + 1}: planning from {vector_text(direction)} "
                                 f"failed ({exc})")
                if other is not None and _total(other[1]) < _total(refined) - TURN_SAVING:
                    axis, refined = other
                    root_notes = [*trial_notes, f"solid {solid_index + 1}: root built along "
                                  f"{vector_text(direction)} (less overhang than as placed)"]
            if auto:
                # Further roots are weighed against the solid as placed, standing or not.
                (axis, refined), root_notes = _turned_further(
                    plan, placed, (direction, area), ((axis, refined), root_notes), notes,
                    planned=root, flipped=thorough)
            notes.extend(root_notes)
        finally:
            if trial is not None:
                trial.stop()
        if with_axes:
            axes.append(_label(axis, refined))
        first = len(pieces)
        pieces.extend(refined)
        parents.extend(_parents_of(refined, first))
    subparts, order, undone = _buildable(pieces, parents, overhang_angle,
                                         tool if check_collisions else None, notes)
    single = _best_single(solids, overhang_angle)
    reason = None if not undone else (
        f"the cut{'s' if len(undone) > 1 else ''} of {', '.join(undone)} undone, as the tool "
        f"would hit the part building {'them' if len(undone) > 1 else 'it'}")
    if reason is None and any(p.blocked is not None for p in pieces):
        reason = TOOL_BLOCKED_CUTS
    return BuildPlan(subparts=subparts, order=order, support_area_single_direction=single[1],
                     notes=notes, overhang_angle=overhang_angle, method=method,
                     single_direction=single[0], axes=axes, support_reason=reason)


#: `BuildPlan.support_reason` of a plan left with overhang that a cut would have saved,
#: had the tool been able to build what lay beyond it (`planner.refine`'s note says which).
TOOL_BLOCKED_CUTS = ("the cuts that would save it were not made: the tool would hit the part "
                     "building what lies beyond them, as the notes say")


def _envelope(tool):
    """The tool's collision envelope (`build_order.tool_envelope`)."""
    from freecad_conformal.decomposition.build_order import tool_envelope

    return tool_envelope(tool)


def _buildable(pieces: list[Piece], parents: list[int | None], angle: float, tool,
               notes: list[str]) -> tuple[list[SubPart], list[int], list[str]]:
    """The sub-parts of `pieces`, a collision-free build order and the names (as first
    planned) of the sub-parts whose cuts were undone for it. Where no order exists, the
    smallest sub-part that could not be placed is built with its parent (the two fused
    back), and the order is sought again: one cut the tool cannot build past the part (a
    side arm just above a wide foot, built sideways into it) cost every other cut of the
    plan, which was then built whole. Raises the order's error when merging leaves no
    cut in any solid (the part built whole is then the caller's to choose) or cannot be
    made."""
    from freecad_conformal.decomposition.build_order import BlockedOrder, build_order

    first_error = None
    undone: list[str] = []
    while True:
        subparts = [_subpart(i, p, parents[i], angle) for i, p in enumerate(pieces)]
        try:
            return subparts, build_order(subparts, tool=tool, notes=notes), undone
        except BlockedOrder as exc:
            # Given up, the plan's own collision is reported, not a merged one's.
            if first_error is None:
                first_error = exc
                first_names = {id(p): s.name for p, s in zip(pieces, subparts)}
            blocked = [i for i in exc.blocked if parents[i] is not None]
            if not blocked:
                raise first_error from None
            merged = min(blocked, key=lambda i: (subparts[i].volume, i))
            into = parents[merged]
            fused = _fused(pieces[into], pieces[merged])
            if fused is None:
                raise first_error from None
            rest = [p for i, p in enumerate(pieces) if i != merged]
            rest[into if into < merged else into - 1] = fused
            if all(p.rule == "root" for p in rest):
                # No cut left: the part built whole is a candidate of its own.
                raise first_error from None
            # Named as first planned: later sub-parts are numbered again after each merge.
            name = first_names[id(pieces[merged])]
            undone.append(name)
            notes.append(f"{name} (along {vector_text(pieces[merged].direction)}) would hit "
                         f"{', '.join(first_names[id(pieces[j])] for j in exc.blocked[merged])}"
                         f": built with {first_names[id(pieces[into])]} instead")
            first_names[id(fused)] = first_names[id(pieces[into])]
            pieces, parents = rest, _regrouped_parents(rest)


def _fused(parent: Piece, child: Piece) -> Piece | None:
    """`child` fused back into `parent` (the cut between them undone), built as the parent
    is; None when OCC's fuse gives no single valid solid."""
    from freecad_conformal.freecad_env import import_freecad

    _, Part = import_freecad()
    try:
        # On copies: pieces of one split share faces and edges, and the fuse's
        # removeSplitter changed shared ones in place (a bobbin's other pieces then read
        # negative volumes, and its merge-back gave up).
        solids = parent.shape.copy().fuse(child.shape.copy()).removeSplitter().Solids
    except Part.OCCError:
        return None
    if len(solids) != 1 or not solids[0].isValid():
        return None
    return Piece(solids[0], parent.direction, parent.base_faces, parent.solid_index,
                 parent.rule, deflection=parent.deflection)


def _regrouped_parents(pieces: list[Piece]) -> list[int | None]:
    """Each piece's parent (`_parents_of`), solid by solid (a solid's pieces are
    consecutive)."""
    parents: list[int | None] = []
    first = 0
    while first < len(pieces):
        last = first
        while last < len(pieces) and pieces[last].solid_index == pieces[first].solid_index:
            last += 1
        parents.extend(_parents_of(pieces[first:last], first))
        first = last
    return parents


def _turned_further(plan: Planner, root: np.ndarray, best_axis: tuple[np.ndarray, float],
                    chosen: tuple, notes: list[str], planned: np.ndarray | None = None,
                    flipped: bool = False) -> tuple:
    """`chosen` ((axis, pieces), the notes saying how they were planned), or the plan from
    a further root where it leaves less overhang, with its notes. The further roots are the
    direction of least whole overhang among the cube's edges and corners, and the one among
    the largest planar faces' (`orientation_candidates`), each where the solid stands on a
    flat face, differs from the roots planned, and leaves the whole solid no more overhang
    than the best axis (`best_axis`: direction, area) and less than the whole solid as
    placed; none once the chosen plan leaves no overhang. With the six axes alone a part
    modelled turned lost its own directions: an L-bracket turned 33° was planned in five
    sub-parts with 356 mm² of overhang left, where standing it on its base leaves 15 mm² in
    one piece. Weighed against what the plan as placed kept instead (its split), a root
    whose split would save most was never planned: a round-bar hook turned 40° kept
    57.4 mm² in four sub-parts as placed, where standing it on its foot (81.5 mm² whole)
    leaves 2.4 mm² in two. A root OCC cannot plan from is noted in `notes` and passed
    over. `planned`: the root `chosen` was planned from where it is not `root` (a solid
    that does not stand as placed, `stands`), not planned again. `flipped`: also the part
    turned over (-`root`), where it keeps no more overhang whole than as placed."""
    solid, angle = plan.solid, plan.angle
    placed_whole = overhang_area(solid, root, angle)
    # `orientation_candidates` lists the cube's directions first, then the faces' own.
    families = (CUBE_DIRECTIONS[len(AXIS_DIRECTIONS):],
                orientation_candidates(solid)[len(CUBE_DIRECTIONS):])
    tried = [root, best_axis[0]] + ([] if planned is None else [planned])
    for family in families:
        family = standing_directions(solid, family)
        if not family:
            continue
        direction, area = best_single_direction(solid, angle, family)
        if (area > best_axis[1] + MIN_SAVING or area >= placed_whole - TURN_SAVING
                or _total(chosen[0][1]) <= MIN_SAVING
                or any(angle_between(direction, d) <= SAME_DIRECTION for d in tried)):
            continue
        tried.append(direction)
        chosen = _kept(plan, direction, chosen, notes)
    turned = -np.asarray(root, dtype=float)
    # Turned over, a part keeps about as much overhang whole as placed, but what its split
    # leaves may differ: CrankArm's arm, 2,714 mm² whole upside down against 2,726 as
    # placed and 1,602 on its side (its best axis), keeps 647 mm² split from there, against
    # 2,477 as placed and 1,170 on its side.
    if (flipped and _total(chosen[0][1]) > MIN_SAVING
            and standing_directions(solid, [turned])
            and overhang_area(solid, turned, angle) < placed_whole + TURN_SAVING
            and not any(angle_between(turned, d) <= SAME_DIRECTION for d in tried)):
        chosen = _kept(plan, turned, chosen, notes)
    return chosen


def _kept(plan: Planner, direction: np.ndarray, chosen: tuple, notes: list[str]) -> tuple:
    """`chosen`, or the plan from `direction` where it leaves less overhang."""
    trial_notes: list[str] = []
    try:
        other = plan(direction, trial_notes)
    except GeometryError as exc:
        notes.append(f"solid {plan.solid_index + 1}: planning from {vector_text(direction)} "
                     f"failed ({exc})")
        return chosen
    if _total(other[1]) < _total(chosen[0][1]) - TURN_SAVING:
        return other, [*trial_notes, f"solid {plan.solid_index + 1}: root built along "
                       f"{vector_text(direction)} (less overhang than the other roots)"]
    return chosen


def _support_free_whole(solid, root: np.ndarray, angle: float) -> np.ndarray | None:
    """The build direction in which the whole solid has no overhang and stands on a flat face
    (geometry/overhang.MIN_BASE_AREA), when the part as placed has overhang; None otherwise.
    Candidates, in order: the cube's 26 directions, then standing the part on one of its
    largest planar faces (geometry/overhang.orientation_candidates)."""
    if overhang_area(solid, root, angle) <= MIN_SAVING:
        return None
    for direction in orientation_candidates(solid):
        if (overhang_area(solid, direction, angle) <= MIN_SAVING
                and base_area(solid, direction) >= MIN_BASE_AREA):
            return direction
    return None


def _label(axis: LazyAxis, pieces: list[Piece]):
    """The solid's axis; cuts along splitting faces meeting its criteria become "axis-face"."""
    for piece in pieces:
        if piece.rule in ("concave-face", "axis-face"):
            probe = SplitCandidate(np.zeros(3), piece.direction, piece.base_faces[0], piece.rule)
            piece.rule = "axis-face" if axis.supports(probe) else "concave-face"
    return axis.get()


def _total(pieces: list[Piece]) -> float:
    return float(sum(p.overhang for p in pieces))



def _best_single(solids: list, angle: float) -> tuple[np.ndarray, float]:
    from freecad_conformal.geometry.overhang import best_single_direction
    from freecad_conformal.freecad_env import import_freecad

    _, Part = import_freecad()
    whole = solids[0] if len(solids) == 1 else Part.Compound(solids)
    # The direction a turn would take (`TURN_SAVING`), so a plan kept as placed for the
    # measure's noise is not shown saving a negative area against it.
    return best_single_direction(whole, angle, tie=TURN_SAVING)


def _subpart(index: int, piece: Piece, parent: int | None, angle: float) -> SubPart:
    axis, rotation = rotation_to(piece.direction, BUILD_AXIS)
    on_bed = parent is None
    if piece.report is not None and piece.report.angle == angle and on_bed == (piece.rule == "root"):
        report = piece.report  # read while planning, with the same base faces
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
    from freecad_conformal.geometry.face_normals import plane_normal

    low = lowest_level(shape, d)
    best = None
    for face in shape.Faces:
        normal = plane_normal(face)
        if normal is None or normal @ d > -1 + PARALLEL_COS_SLACK:
            continue
        if abs(float(np.array(tuple(face.Vertexes[0].Point)) @ d) - low) > LEVEL_TOLERANCE:
            continue
        if best is None or face.Area > best.Area:
            best = face
    return best


def _parents_of(pieces: list[Piece], offset: int) -> list[int | None]:
    """Parent of each piece: the other piece sharing most of its base faces (a cut made
    early may end up resting on a piece split off later)."""
    parents: list[int | None] = []
    for index, piece in enumerate(pieces):
        if not piece.base_faces:
            parents.append(None)
            continue
        shares = [(sum(touch_area(other.shape, f) for f in piece.base_faces), j)
                  for j, other in enumerate(pieces) if j != index]
        area, j = max(shares) if shares else (0.0, None)
        if j is None or area <= 0:
            raise GeometryError(f"sub-part {offset + index + 1} rests on no other sub-part")
        parents.append(offset + j)
    return parents
