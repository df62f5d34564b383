"""Planning one solid's pieces from a root direction: the refinement by cuts.

A `Piece` is a solid built along a direction, with the faces it rests on. `Planner` plans
one solid: while a piece keeps overhang, the candidate cuts are tried (decomposition/cuts.py,
searched in decomposition/cut_search.py) and the one leaving the least total overhang is
made; the piece beyond it becomes a child built along the cut plane's normal, and both are
refined again. A cut that saves nothing is not made; members leaving one face along the build
direction become pieces built on it (decomposition/members.py).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from freecad_conformal.geometry.concave_edges import concave_edges
from freecad_conformal.geometry.frames import vector_text
from freecad_conformal.geometry.splitting_faces import SplitCandidate, split_solid
from freecad_conformal.decomposition.cut_search import CutSearch, best_cut
from freecad_conformal.decomposition.cuts import (LazyAxis, SavingEstimate, area_jump_candidates,
                                             branch_candidates, face_candidates,
                                             flange_candidates)
from freecad_conformal.geometry.overhang import lowest_level, overhang_report
from freecad_conformal.geometry.shape_parts import faces as faces_of, heights as vertex_heights, vertex_points
from freecad_conformal.tolerances import (
    BASE_LEVEL_TOLERANCE, PARALLEL_COS_SLACK, SAME_DIRECTION_ANGLE)

#: A cut must save at least this much overhang (mm², and this fraction of the piece's) to
#: be worth a new sub-part: below it the split only adds a turn of the table and a seam.
#: The fraction stops chains of slivers: the fan built as placed (+Z) had 15 area-jump cuts
#: in a row, each taking a 7-75 mm³ sliver off a blade for 1-10 % of the hub's overhang
#: (the first 10.5 of 855 mm²), 37 s of its plan, and then lost to the plan from the side.
#: Every cut of the plans chosen for the shared parts, the samples and the own parts saves
#: 4.3 % or more (the fan's last: 3.1 of 72.6 mm²); their G-code is the same with 2 %.
MIN_SAVING = 1e-3
MIN_SAVING_FRACTION = 0.02
SAME_DIRECTION = SAME_DIRECTION_ANGLE
#: A piece reaches its base level when its lowest point is within this (mm) of it.
LEVEL_TOLERANCE = BASE_LEVEL_TOLERANCE
#: A cut may not leave a sub-part thinner than this (mm) along its build direction: such a
#: sliver (a plane a hair off a face of CrankArm's stepped end) holds a few layers at most,
#: costs a turn of the table for them, and below the thinnest layer (0.1 mm) the layer
#: planner cannot build it at all: its volume would be left out of the print.
MIN_SUBPART_THICKNESS = 1.0


@dataclass
class Piece:
    """A solid built along `direction`, resting on `base_faces` (its parent's cut regions;
    none for a root on the bed), with what is measured of it kept for the search."""

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
    #: the overhang report (geometry/overhang.py) in `direction`, read once
    report: object = None
    #: (report, per-face share of its overhang the keeper of a cut has): cut_search's cache
    keeper_factor: tuple | None = None
    #: the overhang (mm²) the best cut of the piece would have left, where no cut was made
    #: as the tool would build into the piece (`cut_search._tool_blocked`); None otherwise
    blocked: float | None = None

    def concave(self) -> list:
        """The piece's concave edges (measured once)."""
        if self._concave is None:
            self._concave = concave_edges(self.shape, within=self.ancestor_concave)
        return self._concave

    def mesh(self):
        """The piece's mesh, None when it has no closed one."""
        from freecad_conformal.geometry.surface_mesh import surface_mesh

        return surface_mesh(self.shape, self.deflection)

    def to_data(self) -> dict:
        """Plain data for another process (the trial child's answer): shapes in OCC's binary
        format, bit for bit (geometry/occ_binary.py), so face indices (and the report's)
        survive the trip and the pieces are those this process would have made."""
        from freecad_conformal.geometry.occ_binary import to_binary

        return {"shape": to_binary(self.shape), "direction": self.direction,
                "base_faces": [to_binary(f) for f in self.base_faces],
                "solid_index": self.solid_index, "rule": self.rule, "overhang": self.overhang,
                "report": self.report, "blocked": self.blocked}

    @classmethod
    def from_data(cls, data: dict) -> "Piece":
        """The piece `to_data` wrote (shapes read back as generic shapes: the typed solid and
        faces are taken out of them)."""
        from freecad_conformal.geometry.occ_binary import from_binary

        piece = cls(from_binary(data["shape"]).Solids[0], data["direction"],
                    [from_binary(written).Faces[0] for written in data["base_faces"]],
                    data["solid_index"], data["rule"])
        piece.overhang = data["overhang"]
        piece.report = data["report"]
        piece.blocked = data["blocked"]
        return piece


@dataclass
class Planner:
    """Plans one solid from a given root direction."""

    solid: object
    solid_index: int
    angle: float
    method: str
    axis_step: float | None
    budget: int
    #: the mesh deflection for the solid and its pieces (default: `mesh_deflection` of the
    #: solid when planning starts)
    deflection: float | None = None
    #: the tool's collision envelope: no cut is made whose child the tool would build into
    #: its piece (`cut_search._tool_blocked`); None: cuts are not checked
    envelope: object = None

    def axis(self, root: np.ndarray) -> LazyAxis:
        """The solid's centroidal axis from `root`, computed when first needed."""
        from freecad_conformal.geometry.centroidal_axis import centroidal_axis

        return LazyAxis(lambda: centroidal_axis(self.solid, method=self.method,
                                                step=self.axis_step, start_direction=root))

    def root_mesh(self):
        """The solid's mesh (geometry/surface_mesh.py), as its pieces' are made."""
        from freecad_conformal.geometry.surface_mesh import mesh_deflection, surface_mesh

        return surface_mesh(self.solid, mesh_deflection(self.solid))

    def _root_piece(self, root: np.ndarray) -> Piece:
        from freecad_conformal.geometry.surface_mesh import mesh_deflection

        return Piece(self.solid, root, [], self.solid_index, "root",
                     deflection=self.deflection or mesh_deflection(self.solid))

    def __call__(self, root: np.ndarray, notes: list[str]):
        """(axis, refined pieces) from `root`."""
        axis = self.axis(root)
        return axis, refine(self._root_piece(root), self.angle, axis, budget=self.budget,
                            notes=notes, envelope=self.envelope)

    def whole(self, root: np.ndarray):
        """(axis, [the solid as one piece built along `root`]): no cut, no members."""
        piece = self._root_piece(root)
        piece.overhang = report_of(piece, self.angle).area
        return self.axis(root), [piece]

    def pieces(self, root: np.ndarray) -> tuple[list, list[str]]:
        """(refined pieces, notes) from `root` (the trial's form: the axis stays lazy)."""
        notes: list[str] = []
        return self(root, notes)[1], notes


def overhang_of(piece: Piece, angle: float) -> float:
    return report_of(piece, angle).area


def refine(piece: Piece, angle: float, axis, budget: int, notes: list[str],
           envelope=None) -> list[Piece]:
    """The piece split (recursively) until no cut saves overhang; at most `budget` pieces;
    none whose child the tool (`envelope`) would build into the piece."""
    report = report_of(piece, angle)
    piece.overhang = report.area
    if piece.overhang <= MIN_SAVING or budget <= 1:
        if budget <= 1 and piece.overhang > MIN_SAVING:
            notes.append(f"stopped splitting at the sub-part limit with {piece.overhang:.3f} mm² "
                         "of overhang left")
        return _members(piece, angle, axis, budget, notes, envelope)
    search = cut_search(envelope)
    needed = search.needed(piece.overhang)
    estimate = SavingEstimate(piece.shape, angle, report)
    best = best_cut(piece, face_candidates(piece.shape, estimate, needed, piece.concave()),
                    angle, search, axis)
    if best is None:
        # A round member's own plane before an area jump: tried after them, an area jump
        # first peeled a sliver off an arm's tip (a Y's arms each kept a 70 mm³ sub-part
        # along X).
        best = best_cut(piece, branch_candidates(piece.shape, piece.direction, angle, estimate,
                                                 needed, piece.concave()), angle, search)
    if best is None:
        # A flange's sides before an area jump: its underside, square to the shaft, makes
        # none, and the jumps where the shaft begins cut a spool's flange along one axis
        # only (half its overhang left).
        best = best_cut(piece, flange_candidates(piece.shape, piece.direction, angle, needed,
                                                 piece.concave()), angle, search)
    if best is None:
        # Section 4's area-jump rule only where no splitting face helps: its sections along
        # three axes cost more than everything else here.
        best = best_cut(piece, area_jump_candidates(piece.shape, piece.direction, estimate,
                                                    needed), angle, search)
    if best is None:
        result = _members(piece, angle, axis, budget, notes, envelope)
        if search.blocked:
            least = min(search.blocked)
            notes.append(f"{len(search.blocked)} cut{'s' if len(search.blocked) > 1 else ''} of "
                         f"a piece built along {vector_text(piece.direction)} not made: building "
                         "what lies beyond, the tool would hit the piece (the best would have "
                         f"left {least:.1f} of its {piece.overhang:.1f} mm² of overhang)")
            for made in result:
                made.blocked = least
        return result
    _, keeper, children = best
    result = refine(keeper, angle, axis, budget - len(children), notes, envelope)
    for child in children:
        result.extend(refine(child, angle, axis, max(budget - len(result), 1), notes, envelope))
    return result


def _members(piece: Piece, angle: float, axis, budget: int, notes: list[str],
             envelope=None) -> list[Piece]:
    """The piece, or its base and the members leaving it (see `decomposition/members.py`), each
    refined again."""
    from freecad_conformal.decomposition.members import member_split

    split = member_split(piece, angle, budget, try_cut) if budget > 2 else None
    if split is None:
        return [piece]
    keeper, children = split
    result = refine(keeper, angle, axis, budget - len(children), notes, envelope)
    for child in children:
        result.extend(refine(child, angle, axis, max(budget - len(result), 1), notes, envelope))
    return result


def cut_search(envelope=None) -> CutSearch:
    """How `best_cut` reads and cuts pieces (looked up at each call, so a test may count
    the exact cuts), with the tool's `envelope` to check cuts against."""
    return CutSearch(try_cut=try_cut, report=report_of, min_saving=MIN_SAVING,
                     min_fraction=MIN_SAVING_FRACTION, level_tolerance=LEVEL_TOLERANCE,
                     same_direction=SAME_DIRECTION, min_thickness=MIN_SUBPART_THICKNESS,
                     envelope=envelope)


def report_of(piece: Piece, angle: float):
    """The piece's overhang report (kept: a cut's pieces are read when the cut is tried and
    again when the winner is refined)."""
    if piece.report is None or piece.report.angle != angle:
        # The trial cuts read the piece's mesh; the report reads its faces' parts of it.
        piece.mesh()
        piece.report = overhang_report(piece.shape, piece.direction, angle, piece.base_faces,
                                        on_bed=piece.rule == "root")
    return piece.report


def try_cut(piece: Piece, candidate: SplitCandidate, angle: float,
             regions: list | None = None, same_direction: bool = False):
    """(total overhang after the cut, kept piece, children) or None when the cut is no use.

    `regions` (default: the candidate's) are cut at once, each child resting on the regions
    it touches; `same_direction` lets children be built along the piece's own direction
    (members, decomposition/members.py), which a cut made to save overhang never wants."""
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
    if _thinner_than(keeper_shape, d, MIN_SUBPART_THICKNESS):
        return None
    keeper = Piece(keeper_shape, d, piece.base_faces, piece.solid_index, piece.rule,
                    ancestor_concave=piece.concave(), deflection=piece.deflection)
    total = overhang_of(keeper, angle)
    children = []
    for shape in pieces:
        if shape is keeper_shape:
            continue
        side = (np.array(tuple(shape.CenterOfMass)) - candidate.point) @ candidate.normal
        direction = candidate.normal if side > 0 else -candidate.normal
        if not same_direction and math.acos(float(np.clip(direction @ d, -1, 1))) < SAME_DIRECTION:
            return None
        if _thinner_than(shape, direction, MIN_SUBPART_THICKNESS):
            return None
        base = regions if len(regions) == 1 else [r for r in regions if touch_area(shape, r) > 0]
        if not base:
            return None
        child = Piece(shape, direction, base, piece.solid_index, candidate.rule,
                       ancestor_concave=piece.concave(), deflection=piece.deflection)
        total += overhang_of(child, angle)
        children.append(child)
    return total, keeper, children


def _thinner_than(shape, direction: np.ndarray, thickness: float) -> bool:
    """Whether `shape` spans less than `thickness` along `direction`. Its vertices answer
    most cases (they lie on the shape, so their span never exceeds the shape's); OCC's exact
    extent the rest. Bounding boxes cannot: a thin slice of a B-spline plate keeps the whole
    control polygon's box (CrankArm: 7.9 mm for a 0.002 mm slice)."""
    from freecad_conformal.geometry.sections import extent_along

    heights = vertex_heights(shape, direction)
    if heights and max(heights) - min(heights) >= thickness:
        return False
    low, high = extent_along(shape, direction)
    return high - low < thickness


def _holds_base(shape, piece: Piece) -> bool:
    """Whether `shape` carries the piece's base faces (always true for a root on the bed)."""
    if not piece.base_faces:
        return True
    # A shared area implies contact: no distance query needed (distToShape on B-spline
    # pieces cost more than the split itself).
    return any(touch_area(shape, face) > 0 for face in piece.base_faces)


def touch_area(shape, region) -> float:
    """Area shared between `region` (a planar face) and the faces of `shape` in its plane."""
    from freecad_conformal.geometry.face_normals import plane_normal

    normal = plane_normal(region)
    level = float(vertex_points(region)[0] @ normal)
    area = 0.0
    for face in faces_of(shape):
        n = plane_normal(face)
        if n is None or abs(abs(n @ normal) - 1) > PARALLEL_COS_SLACK:
            continue
        if abs(float(vertex_points(face)[0] @ normal) - level) > LEVEL_TOLERANCE:
            continue
        if face.BoundBox.intersect(region.BoundBox):
            area += float(face.common(region).Area)
    return area
