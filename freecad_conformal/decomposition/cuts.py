"""Candidate cuts for the decomposition, ranked before any Boolean (decomposition/decompose.py).

A cut is tried exactly (a Boolean split and an overhang evaluation of every piece, the
costly part) only when an estimate from the piece's faces says it could save overhang:
`SavingEstimate` re-reads the piece's overhanging faces on one side of a plane in the
direction that side would be built in. The estimate reads only the plane, so splitting-face
planes and area-jump planes are ranked before their interior regions (a section Boolean and
inside tests each) are computed, and only for the best ones.

The centroidal axis enters only through criteria 1 and 3 of METHODS section 3 (which regions
meet a break link): among candidates whose estimated savings tie and whose exact cuts leave
the same total, those meeting the criteria win; and it labels the cuts "axis-face".
`LazyAxis` computes it the first time such a tie needs it, or at the end for the labels and
the plan: a root direction tried and rejected by `root_direction="auto"` then usually never
pays for its axis (13 s of CrankArm's arm).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Iterator

import numpy as np

from freecad_conformal.geometry.concave_edges import concave_edges
from freecad_conformal.geometry.shape_cache import ShapeCache
from freecad_conformal.geometry.splitting_faces import SplitCandidate

#: Candidate cuts split exactly per refinement step, best estimated saving first: the
#: estimate ranks well enough that the winner is among the first few, and each exact split
#: is a Boolean plus an overhang evaluation of every piece. (Taking the first that saves
#: anything instead leads CrankArm's greedy search elsewhere: 15 sub-parts in 25 s.)
MAX_EXACT_CUTS = 3

#: Area-jump planes (largest ∂ first) whose saving is estimated: the mesh profile and the
#: estimate are cheap, so all jumps of a piece are ranked by what they could save.
JUMP_PLANES = 64

#: Two estimated savings closer than this (mm²) are a tie: regions of all tied planes are
#: computed, and the axis criteria break the tie.
SAVING_TIE = 1e-9


class LazyAxis:
    """The centroidal axis of one solid from its root direction, computed on first use."""

    def __init__(self, compute: Callable[[], object]) -> None:
        self._compute = compute
        self._axis = None

    @property
    def computed(self) -> bool:
        return self._axis is not None

    def get(self):
        if self._axis is None:
            self._axis = self._compute()
        return self._axis

    def supports(self, candidate: SplitCandidate) -> bool:
        """Criteria 1 and 3 (METHODS section 3) for the candidate's region."""
        points = (candidate.boundary if candidate.boundary is not None
                  else boundary_points(candidate.region))
        return self.get().supports_split(candidate.normal, points)


def boundary_points(face) -> np.ndarray:
    """Points of a face's outer boundary (vertices and a few points along curved edges)."""
    return np.array([tuple(p) for p in face.OuterWire.discretize(Number=32)])


class SavingEstimate:
    """How much overhang a cut could save: the piece's overhanging faces on one side of the
    plane, re-read in the direction that side would be built in (the plane's normal away
    from the other side). An estimate for ranking: the exact split decides. It reads only
    the plane, so planes are ranked before their regions are computed."""

    def __init__(self, shape, angle: float, report) -> None:
        from freecad_conformal.geometry.face_normals import plane_normal
        from freecad_conformal.geometry.overhang import overhang_threshold
        from freecad_conformal.geometry.surface_mesh import face_part, mesh_deflection

        self.threshold = overhang_threshold(angle)
        faces = shape.Faces
        deflection = mesh_deflection(shape)
        self.faces = []
        for index, area in report.faces:
            face = faces[index]
            normal = plane_normal(face)
            surface = normal if normal is not None else face_part(face, deflection)
            self.faces.append((np.array(tuple(face.CenterOfMass)), area, surface))
        # Each face's overhang by direction: the candidate planes of a piece share few
        # normals (area-jump planes along three axes, parallel faces), and reading a curved
        # face's mesh again for each cost the fan's +Z plan 1.3 s.
        self._read: dict[tuple[int, bytes], float] = {}

    def _overhang(self, index: int, d: np.ndarray) -> float:
        key = (index, d.tobytes())
        if key not in self._read:
            _, area, surface = self.faces[index]
            if isinstance(surface, np.ndarray):
                self._read[key] = area if surface @ d < -self.threshold else 0.0
            else:
                self._read[key] = min(area, surface.below(d, self.threshold))
        return self._read[key]

    def saving(self, candidate: SplitCandidate) -> float:
        n = candidate.normal
        sides = {1.0: 0.0, -1.0: 0.0}
        for index, (centre, area, _) in enumerate(self.faces):
            side = 1.0 if (centre - candidate.point) @ n > 0 else -1.0
            sides[side] += area - self._overhang(index, side * n)
        return max(sides.values())


@dataclass
class PlaneCandidates:
    """One plane worth a cut: its estimated saving, and its interior regions (restricted to
    those touching `edges` [(face index, concave edges)] when given), read exactly (a
    section Boolean, computed once when first asked) or on the piece's mesh (cheap)."""

    saving: float
    point: np.ndarray
    normal: np.ndarray
    rule: str
    exact: Callable[[], list[SplitCandidate]]
    edges: list | None = None
    _regions: list[SplitCandidate] | None = field(default=None, repr=False)

    def regions(self) -> list[SplitCandidate]:
        """The exact regions, as cut candidates."""
        if self._regions is None:
            self._regions = self.exact()
        return self._regions

    def mesh_regions(self, mesh) -> list:
        """The regions on `mesh` (decomposition/mesh_cut.py), in the order of `regions()`."""
        from freecad_conformal.decomposition.mesh_cut import mesh_regions

        touching = None if self.edges is None else [
            (index, [edge_points(e.edge) for e in edge_list]) for index, edge_list in self.edges]
        found = mesh_regions(mesh, self.point, self.normal, touching)
        return sorted(found, key=lambda r: -1 if r.face_index is None else r.face_index)


def edge_points(edge) -> np.ndarray:
    """Points along an edge, at its vertices and 32 steps between."""
    return np.array([tuple(p) for p in edge.discretize(Number=33)])


def area_jump_candidates(shape, direction: np.ndarray, estimate: SavingEstimate,
                         needed: float) -> Iterator[PlaneCandidates]:
    """The best MAX_EXACT_CUTS area-jump planes worth a cut, best first: the planes are
    ranked before their regions are computed, and a plane's exact regions (a section
    Boolean) are computed only when `regions()` is called."""
    from freecad_conformal.geometry.area_jumps import area_jump_planes, plane_candidates

    planes = []
    for _, point, normal in area_jump_planes(shape, direction, exact=False, limit=JUMP_PLANES):
        saving = estimate.saving(SplitCandidate(point, normal, None, "area-jump"))
        if saving > needed:
            planes.append((saving, point, normal))
    planes.sort(key=lambda item: -item[0])
    # The best few only, ties or not: a staircase of area jumps (CrankArm's curved end)
    # ties dozens of planes, each worth a Boolean.
    for saving, point, normal in planes[:MAX_EXACT_CUTS]:
        yield PlaneCandidates(saving, point, normal, "area-jump",
                              lambda point=point, normal=normal: plane_candidates(shape, point, normal))


#: A branch's plane lies this far (mm) beyond the farthest point of the concave edges where
#: it leaves the piece, about a layer: through that point the plane would only touch the
#: junction curve there, a section OCC may split in slivers.
BRANCH_CLEARANCE = 0.2

#: Surfaces whose axis is a member's own direction.
BRANCH_SURFACES = ("Cylinder", "Cone")


def branch_candidates(shape, direction: np.ndarray, angle: float, estimate: SavingEstimate,
                      needed: float, concave: list | None = None) -> Iterator[PlaneCandidates]:
    """Planes square to members that leave the piece leaning beyond the overhang angle (a
    Y's or a coat rack's arms, a tee's branch, a knob's lever), best estimated saving first,
    as `area_jump_candidates`: METHODS section 3's fallback where no planar splitting face
    exists ("silhouette edges"). A member's axis is that of a cylinder or cone carrying
    concave edges (where the member meets the rest), or the one direction along all the
    planar sides of a prismatic member (`_prism_members`). The plane is normal to it,
    pointing along the member, just beyond the farthest point of those edges: the member
    is then cut off whole, to be built along its own axis. Area-jump planes only run along
    ±X, ±Y, ±Z, and cut an arm leaning 20° above the horizontal through its stem; a tab
    leaving a round body makes no area jump at all (the body's section shrinks to nothing
    where the tab goes on)."""
    if concave is None:
        concave = concave_edges(shape)
    lean = math.cos(angle)
    planes = []
    for key, normal, origin, points in _round_members(shape, concave) + _prism_members(shape, concave):
        if float(normal @ direction) > lean:
            continue        # a member within the overhang angle grows from the piece as it is
        height = float(np.max(points @ normal)) + BRANCH_CLEARANCE
        point = origin + (height - float(origin @ normal)) * normal
        saving = estimate.saving(SplitCandidate(point, normal, None, "branch"))
        if saving > needed:
            planes.append((saving, key, point, normal))
    planes.sort(key=lambda item: (-item[0], item[1]))
    for saving, _, point, normal in planes[:MAX_EXACT_CUTS]:
        yield PlaneCandidates(saving, point, normal, "branch",
                              lambda point=point, normal=normal: _branch_regions(shape, point, normal))


#: Planes along a shaft under a flange, at this many directions evenly round it: eight
#: leave the corners of an octagon round the shaft, four those of a square (a spool's r 15
#: tube: 58.7 against 217.3 mm²). With --support, a spool with bolt holes then printed
#: 0.94 cm³ of support under its upper flange instead of 2.59, for four more small
#: sub-parts: 0.600 of PrusaSlicer's material with supports instead of 0.630, and 0.665
#: of its time instead of 0.653.
FLANGE_SIDES = 8


def flange_candidates(shape, direction: np.ndarray, angle: float, needed: float,
                      concave: list | None = None) -> Iterator[PlaneCandidates]:
    """Planes along a shaft, just clear of it, where a flange overhangs it (a spool's upper
    flange, a pulley's rim, a bobbin's cheek): the flange's overhanging underside meets the
    shaft's cylinder at a concave circle, all round (`_all_round`). Square to the shaft,
    the underside makes no area jump, and a plane through the shaft's axis would split the
    shaft as well; the planes
    `FLANGE_SIDES` ways round, at the shaft's radius plus `BRANCH_CLEARANCE` (touching the
    cylinder, OCC may split in slivers), cut off the flange's sides beyond the shaft, each
    built outwards along the plane's normal, leaving the corners between them over the
    shaft. A plane's estimated saving is the underside's exact area beyond it
    (`_area_beyond`): `SavingEstimate` reads whole faces by their centres, and the
    underside's lies on the shaft's axis, inside every plane; read off its mesh, the
    planes' savings differed with OCCT's meshing, and so did which of them came first.
    Best first, at most `MAX_EXACT_CUTS`, as `area_jump_candidates`."""
    from freecad_conformal.geometry.face_normals import plane_normal
    from freecad_conformal.geometry.frames import perpendicular_frame

    if concave is None:
        concave = concave_edges(shape)
    faces = shape.Faces
    threshold = math.cos(angle)
    shafts: dict[int, set[int]] = {}
    for edge_angle in concave:
        kinds = [type(faces[index].Surface).__name__ for index in edge_angle.faces]
        if sorted(kinds) != ["Cylinder", "Plane"] or not _all_round(edge_angle.edge):
            continue
        shaft, underside = (edge_angle.faces[kinds.index(kind)] for kind in ("Cylinder", "Plane"))
        normal = plane_normal(faces[underside])
        if (normal is not None and abs(float(normal @ _axis(faces[shaft]))) >= SQUARE_COS
                and float(normal @ direction) < -threshold):
            shafts.setdefault(shaft, set()).add(underside)
    planes = []
    for shaft, undersides in sorted(shafts.items()):
        surface = faces[shaft].Surface
        centre = np.array(tuple(surface.Center), dtype=float)
        for k, normal in enumerate(_around(perpendicular_frame(_axis(faces[shaft])))):
            point = centre + (float(surface.Radius) + BRANCH_CLEARANCE) * normal
            saving = sum(_area_beyond(faces[i], point, normal) for i in sorted(undersides))
            if saving > needed:
                planes.append((saving, shaft, k, point, normal))
    # A round flange's planes save the same to the last few bits: ties go by the shaft and
    # the turn, not by how OCC rounded each area.
    planes.sort(key=lambda item: (-round(item[0], SAVING_DIGITS), item[1], item[2]))
    for saving, _, _, point, normal in planes[:MAX_EXACT_CUTS]:
        yield PlaneCandidates(saving, point, normal, "flange",
                              lambda point=point, normal=normal: _branch_regions(
                                  shape, point, normal, "flange"))


#: An underside whose normal is within this (|cos|) of a shaft's axis is square to it.
SQUARE_COS = 1.0 - 1e-9
#: Flange planes' savings (mm²) are compared to this many decimals.
SAVING_DIGITS = 6


#: Each underside's area beyond each plane, by face identity: a cut leaves the undersides
#: of the flanges it does not divide untouched, and the planes are weighed again at every
#: refinement of the piece (a bobbin's two flanges: 528 Booleans, 1.2 s, before this).
_BEYOND: ShapeCache[dict] = ShapeCache(limit=4096, oriented=False)


def _area_beyond(face, point: np.ndarray, normal: np.ndarray) -> float:
    """The area (mm²) of a planar `face` on the side of the plane through `point` that
    `normal` points to: a Boolean with the half-space's box beyond the face's."""
    return _BEYOND.get_keyed((face,), (point.tobytes(), normal.tobytes()),
                             lambda: _area_beyond_now(face, point, normal))


def _area_beyond_now(face, point: np.ndarray, normal: np.ndarray) -> float:
    from freecad_conformal.freecad_env import import_freecad
    from freecad_conformal.geometry.boxes import box_reach
    from freecad_conformal.geometry.splitting_faces import plane_through

    App, _ = import_freecad()
    box = face.BoundBox
    if box_reach(box, normal) <= float(point @ normal):
        return 0.0
    reach = box.DiagonalLength + 1.0
    beyond = plane_through(point, normal, box).extrude(App.Vector(*(reach * normal)))
    return float(face.common(beyond).Area)


def _axis(face) -> np.ndarray:
    """The unit axis of a cylindrical face."""
    axis = np.array(tuple(face.Surface.Axis), dtype=float)
    return axis / np.linalg.norm(axis)


def _all_round(edge) -> bool:
    """Whether `edge` is a whole circle: a flange round its shaft. Where a plate meets a
    boss along an arc (CrankArm's arm), the planes along the boss cut the plate itself:
    its arm kept 504 mm² of overhang instead of 1,170, but took 3 s more to plan (2.8 ->
    5.8 s of choice) for 4 % more material in the part."""
    return type(edge.Curve).__name__ == "Circle" and edge.isClosed()


def _around(frame: np.ndarray) -> list[np.ndarray]:
    """`FLANGE_SIDES` unit directions evenly round, in the plane of the frame's two rows."""
    turns = [2.0 * math.pi * k / FLANGE_SIDES for k in range(FLANGE_SIDES)]
    return [math.cos(t) * frame[0] + math.sin(t) * frame[1] for t in turns]


Member = tuple[tuple, np.ndarray, np.ndarray, np.ndarray]
"""(sort key, axis pointing along the member, a point on the axis, its concave edges' points)"""


def _round_members(shape, concave: list) -> list[Member]:
    """Cylinders and cones carrying concave edges, along their axes (towards the face's
    centre)."""
    faces = shape.Faces
    ends: dict[int, list[np.ndarray]] = {}
    for edge_angle in concave:
        for index in edge_angle.faces:
            if type(faces[index].Surface).__name__ in BRANCH_SURFACES:
                ends.setdefault(index, []).append(edge_points(edge_angle.edge))
    members = []
    for index, pieces in sorted(ends.items()):
        surface = faces[index].Surface
        axis = np.array(tuple(surface.Axis), dtype=float)
        axis /= np.linalg.norm(axis)
        points = np.vstack(pieces)
        outward = 1.0 if (np.array(tuple(faces[index].CenterOfMass)) - points.mean(axis=0)) @ axis > 0 else -1.0
        members.append(((0, index), outward * axis, np.array(tuple(surface.Center), dtype=float), points))
    return members


#: Two planar sides whose normals lie closer than this (rad) are parallel: they give no
#: member axis; a side whose normal is this close to square to an axis runs along it.
PRISM_ANGLE = math.radians(1.0)


def _prism_members(shape, concave: list) -> list[Member]:
    """Members with planar sides leaving a round body (a knob's lever, a cylinder's ears):
    every direction square to the normals of two non-parallel planar faces meeting a curved
    face at concave edges, pointing from those edges towards the faces' centres; the
    member's sides are the faces of such edges that run along it, each pointing that way.
    A member leaving a planar face is the splitting faces' (a square branch on a block's
    top, cut off along its axis, was built into the block: no order, and the part whole)."""
    from freecad_conformal.geometry.face_normals import plane_normal

    faces = shape.Faces
    sides: dict[int, list[np.ndarray]] = {}
    for edge_angle in concave:
        planar = [index for index in edge_angle.faces if plane_normal(faces[index]) is not None]
        if len(planar) == 1:
            sides.setdefault(planar[0], []).append(edge_points(edge_angle.edge))
    found = [(index, plane_normal(faces[index]), np.vstack(pieces),
              np.array(tuple(faces[index].CenterOfMass))) for index, pieces in sorted(sides.items())]
    axes: list[np.ndarray] = []
    for i, (_, first, _, _) in enumerate(found):
        for _, second, _, _ in found[i + 1:]:
            across = np.cross(first, second)
            if np.linalg.norm(across) < math.sin(PRISM_ANGLE):
                continue
            axis = across / np.linalg.norm(across)
            if not any(abs(float(axis @ known)) > math.cos(PRISM_ANGLE) for known in axes):
                axes.append(axis)
    members = []
    for number, axis in enumerate(axes):
        for outward in (axis, -axis):
            along = [points for _, normal, points, centre in found
                     if abs(float(normal @ axis)) < math.sin(PRISM_ANGLE)
                     and float((centre - points.mean(axis=0)) @ outward) > 0]
            if len(along) >= 2:
                points = np.vstack(along)
                members.append(((1, number, float(outward @ axis)), outward, points.mean(axis=0), points))
    return members


def _branch_regions(shape, point: np.ndarray, normal: np.ndarray,
                    rule: str = "branch") -> list[SplitCandidate]:
    from freecad_conformal.geometry.splitting_faces import interior_regions

    return [SplitCandidate(point, normal, region, rule)
            for region in interior_regions(shape, point, normal)]


def face_candidates(shape, estimate: SavingEstimate, needed: float,
                    concave: list | None = None) -> Iterator[PlaneCandidates]:
    """The planes of splitting faces worth a cut, best first, as `area_jump_candidates`.
    `concave`: the shape's concave edges when known."""
    from freecad_conformal.geometry.splitting_faces import candidate_planes, plane_regions

    if concave is None:
        concave = concave_edges(shape)
    planes = [(estimate.saving(plane.probe()), order, plane) for order, plane
              in enumerate(candidate_planes(shape, concave))]
    planes = sorted((p for p in planes if p[0] > needed), key=lambda item: (-item[0], item[1]))
    for saving, _, plane in planes:
        yield PlaneCandidates(saving, plane.point, plane.normal, "concave-face",
                              lambda plane=plane: sorted(plane_regions(shape, plane),
                                                         key=lambda r: r.face_index),
                              plane.faces)


def axis_first(trials: list, axis: LazyAxis | None, tolerance: float) -> list:
    """`trials` [(saving, candidate, result)] in rank order, with candidates meeting the axis
    criteria moved first within each tie of estimated saving — computed (and the axis with
    it) only when two tied candidates' exact totals are within `tolerance`, the one case in
    which their order picks the winner."""
    if axis is None:
        return trials
    decisive = any(abs(a[0] - b[0]) <= SAVING_TIE and a[2] is not None and b[2] is not None
                   and abs(a[2][0] - b[2][0]) <= tolerance
                   for i, a in enumerate(trials) for b in trials[i + 1:])
    if not decisive:
        return trials
    for _, candidate, _ in trials:
        if candidate.rule == "concave-face" and axis.supports(candidate):
            candidate.rule = "axis-face"
    order = sorted(range(len(trials)), key=lambda i: (
        -trials[i][0], 0 if trials[i][1].rule == "axis-face" else 1, i))
    return [trials[i] for i in order]
