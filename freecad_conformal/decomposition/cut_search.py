"""The search for a piece's best cut (decomposition/decompose.py).

Candidate planes come ranked by the saving estimated from the piece's faces
(decomposition/cuts.py). Their regions are tried on the piece's mesh (decomposition/mesh_cut.py), and only the
cuts the mesh ranks best are made exactly: each is a section Boolean for the region and a
split, where the mesh trial is a few array operations. A piece without a closed mesh has
every region cut exactly, as the search did before meshes. A trial cut whose child the
tool would build into the piece's side of the faces it divides is not made at all
(`_tool_blocked`): no order could build it.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Iterable, Iterator

import numpy as np

from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry.splitting_faces import SplitCandidate
from freecad_conformal.decomposition.cuts import (MAX_EXACT_CUTS, SAVING_TIE, LazyAxis,
                                             PlaneCandidates, axis_first)
from freecad_conformal.decomposition.mesh_cut import mesh_overhang, mesh_trial
from freecad_conformal.geometry.face_normals import plane_normal
from freecad_conformal.geometry.overhang import lowest_level, overhang_threshold
from freecad_conformal.geometry.shape_parts import faces as faces_of
from freecad_conformal.tolerances import DIVISION_GUARD


@dataclass(frozen=True)
class CutSearch:
    """What the search needs from the decomposition: `try_cut(piece, candidate, angle)`,
    the exact cut ((total, keeper, children) or None); `report(piece, angle)`, the piece's
    overhang report; the least saving worth a cut (mm², and fraction of the piece's
    overhang); and the tolerances a cut's pieces are judged with."""

    try_cut: Callable
    report: Callable
    min_saving: float
    min_fraction: float
    level_tolerance: float
    same_direction: float
    #: the least span (mm) of a cut's pieces along their build directions
    min_thickness: float = 0.0
    #: the tool's collision envelope (process/tools.Envelope): a trial cut whose child the
    #: tool cannot build without meeting the piece it is cut from is not made (None: no
    #: such check, as `decompose(check_collisions=False)`)
    envelope: object = None
    #: the overhang (mm², total after the cut) of each trial cut left unmade for that
    blocked: list = field(default_factory=list)

    def needed(self, overhang: float) -> float:
        """The least saving worth a cut of a piece with this much overhang (mm²)."""
        return max(self.min_saving, self.min_fraction * overhang)


def best_cut(piece, planes: Iterable[PlaneCandidates], angle: float, search: CutSearch,
             axis: LazyAxis | None = None):
    """The cut leaving the least total overhang: (total, keeper, children), or None when
    none saves overhang.

    `planes` come best estimated saving first (read from the piece's overhanging faces, no
    Boolean). Their regions are tried, until MAX_EXACT_CUTS have been, finishing the tie of
    estimated saving the last belongs to; among tied candidates, those meeting the axis
    criteria come first. Trials run on the piece's mesh (decomposition/mesh_cut.py) when it has
    one: only the cuts the mesh ranks best are then made exactly, and none when the mesh
    says no cut saves anything.
    """
    needed = search.needed(piece.overhang)
    mesh = piece.mesh()
    trials = []
    for tie in _ties(planes, needed):
        if len(trials) >= MAX_EXACT_CUTS:
            break
        for plane in tie:
            if mesh is None:
                trials.extend((plane.saving, candidate, search.try_cut(piece, candidate, angle))
                              for candidate in plane.regions())
                continue
            for region in plane.mesh_regions(mesh):
                candidate = SplitCandidate(plane.point, plane.normal, None, plane.rule,
                                           region.face_index, region.boundary_points())
                trial = _mesh_trial(piece, mesh, region, angle, search)
                trials.append((plane.saving, candidate,
                               None if trial is None else (trial.total, plane, region, trial)))
    ordered = axis_first(trials, axis, search.min_saving)
    if mesh is not None:
        ordered = _made_exactly(piece, mesh, ordered, angle, needed, search)
    best = None
    for _, _, trial in ordered:
        if trial is not None and (best is None or trial[0] < best[0] - search.min_saving):
            best = trial
    return best if best is not None and best[0] <= piece.overhang - needed else None


#: Mesh trials whose totals lie within this fraction of the piece's overhang (and
#: the least saving) of the best are all made exactly, the exact totals deciding: the mesh reads
#: CrankArm's cuts within 0.02 % (0.5 mm² of 2726), symmetric cuts tie exactly.
MESH_MARGIN = 5e-3
#: A probe this close (mm) to a region's boundary is inside it: the probe sits two mesh
#: deflections inside the mesh region, far from the edge.
INSIDE_REGION = 1e-6


def _mesh_trial(piece, mesh, region, angle: float, search: CutSearch):
    return mesh_trial(mesh, region, piece.direction, overhang_threshold(angle),
                      _keeper_factor(piece, angle, search), lowest_level(piece.shape, piece.direction),
                      search.level_tolerance, search.same_direction, search.min_thickness,
                      on_bed=not piece.base_faces)


def _keeper_factor(piece, angle: float, search: CutSearch) -> np.ndarray:
    """Per face, the share of its overhang the piece keeps in its own direction: below 1
    for planar faces resting (partly) on the bed or the base faces, 0 for curved faces
    laid on the bed."""
    report = search.report(piece, angle)
    if piece.keeper_factor is None or piece.keeper_factor[0] is not report:
        piece.keeper_factor = (report, _factor_of(piece, report, angle))
    return piece.keeper_factor[1]


def _factor_of(piece, report, angle: float) -> np.ndarray:
    overhang = dict(report.faces)
    threshold = overhang_threshold(angle)
    faces = faces_of(piece.shape)
    factor = np.ones(len(faces))
    for index, face in enumerate(faces):
        normal = plane_normal(face)
        if normal is not None and normal @ piece.direction < -threshold:
            factor[index] = overhang.get(index, 0.0) / max(float(face.Area), DIVISION_GUARD)
    # Laid on the bed (`overhang.overhang_report`): none of it overhangs while the kept
    # piece stands there.
    factor[report.laid] = 0.0
    return factor


def _made_exactly(piece, mesh, ordered: list, angle: float, needed: float,
                  search: CutSearch) -> list:
    """The mesh trials `ordered` [(saving, candidate, (mesh total, plane, region) | None)]
    with the best made exactly: [(saving, exact candidate, exact trial)] in the same order.
    Empty when the mesh says no cut saves `needed` (against the mesh's own reading of the
    uncut piece, so that both carry the same error)."""
    valid = [item for item in ordered if item[2] is not None]
    if not valid:
        return []
    uncut = mesh_overhang(mesh, piece.direction, overhang_threshold(angle),
                          _keeper_factor(piece, angle, search))
    best = min(item[2][0] for item in valid)
    if best > uncut - needed:
        return []
    margin = max(search.min_saving, MESH_MARGIN * piece.overhang)
    near = [item for item in valid if item[2][0] <= best + margin]
    rest = sorted((item for item in valid if item[2][0] > best + margin), key=lambda i: i[2][0])
    made = []
    for saving, candidate, (total, plane, region, trial) in near + rest:
        if len(made) >= len(near) and any(t is not None and t[0] <= piece.overhang - needed
                                          for _, _, t in made):
            break
        if len(made) >= MAX_EXACT_CUTS and len(made) >= len(near):
            break
        if _tool_blocked(trial, search, plane if plane.rule == "flange" else None):
            search.blocked.append(total)
            continue
        exact = _exact_region(plane, region, mesh)
        if exact is None:
            continue
        exact.rule = candidate.rule
        made.append((saving, exact, search.try_cut(piece, exact, angle)))
    return made


def _tool_blocked(trial, search: CutSearch, flange=None) -> bool:
    """Whether the tool building the trial's child would meet the faces the cut divides,
    on the piece's side (the child's own faces, carried on where the piece keeps them):
    a cut into a coil spring's wire, built along −X inside the coil. That cut would be
    undone once its sub-parts are ordered (`decompose._buildable` fuses a blocked child
    back into its parent), after its exact split (7 s of the coil's 18 s decomposition),
    and the part built whole. Only those faces: the rest of the piece may yet be cut off
    and built after the child (a post's collar beside the arm above it), where the order
    decides. A `flange` plane's child is built outwards past all of the piece beyond the
    plane (a bobbin's other cheek, which stays on the bed): its sixteen flange cuts were
    all undone, and took 9.6 s of its plan instead of 2.8. Read on the mesh's two parts,
    sampled as `geometry/collision.py` samples sub-parts."""
    if search.envelope is None or trial.triangles is None:
        return False
    from freecad_conformal.geometry.collision import builds_into, sample_spacing, spread_samples

    (keeper, keeper_faces), (child, child_faces) = trial.triangles()
    if flange is None:
        divided = np.isin(keeper_faces, child_faces)
    else:
        divided = (keeper.mean(axis=1) - flange.point) @ flange.normal > 0.0
    if not divided.any() or not len(child):
        return False
    spacing = sample_spacing(search.envelope)
    obstacle = keeper[divided]
    return builds_into(spread_samples(child.reshape(-1, 3), child, spacing),
                       trial.children[0][0], search.envelope,
                       spread_samples(obstacle.reshape(-1, 3), obstacle, spacing))


def _exact_region(plane: PlaneCandidates, region, mesh) -> SplitCandidate | None:
    """The exact region of the plane holding the mesh region's inner point."""
    App, _ = import_freecad()
    inner = region.polygon.buffer(-2.0 * mesh.deflection)
    probe = region.inner_point() if inner.is_empty else region.to_3d(
        [inner.representative_point().x, inner.representative_point().y])[0]
    point = App.Vector(*(float(c) for c in probe))
    for candidate in plane.regions():
        if candidate.region.isInside(point, INSIDE_REGION, True):
            return candidate
    return None


def _ties(planes: Iterable[PlaneCandidates], needed: float) -> Iterator[list]:
    """Groups of planes of equal estimated saving (best first), those estimated to save
    more than `needed`."""
    group: list = []
    for item in planes:
        if item.saving <= needed:
            break
        if group and group[0].saving - item.saving > SAVING_TIE:
            yield group
            group = []
        group.append(item)
    if group:
        yield group
