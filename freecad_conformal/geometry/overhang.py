"""Overhang (support) area of a solid built along a direction.

A point of the surface overhangs when its outward normal n faces down more steeply than the
allowed angle α from the build direction d: n·d < −sin α (a wall, n ⊥ d, is 0° of overhang;
a ceiling, n = −d, is 90°). Planar faces are exact (`Face.Area`); curved faces are integrated
on their part of the solid's mesh (geometry/surface_mesh.py: OCC's exact normals at the
corners, areas scaled to the exact Face.Area so the chord error does not bias the total).
Faces resting on the bed (the lowest plane) or on the parent's split faces are excluded.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

from freecad_conformal.errors import PlanError
from freecad_conformal.geometry.face_normals import plane_normal
from freecad_conformal.geometry.shape_cache import ShapeCache
from freecad_conformal.geometry.shape_parts import faces as faces_of, heights as vertex_heights, vertex_points
from freecad_conformal.geometry.surface_mesh import (BED_BAND, PLANE_RUN, face_part, laid_at, mesh_deflection,
                                                     mesh_faces)
from freecad_conformal.tolerances import PARALLEL_COS_SLACK, ROUNDING_SLACK, ZERO_LENGTH

#: Default allowed overhang from the build direction (the common 45° self-support rule of FDM).
DEFAULT_OVERHANG_ANGLE = math.radians(45.0)

#: A planar face counts as lying on a plane (bed, split face) within this distance (mm):
#: far above OCC's 1e-7 confusion, far below any layer height.
ON_PLANE_TOLERANCE = 1e-4

#: Overhang areas below this (mm²) are rounding: slivers of tangent faces.
NEGLIGIBLE_AREA = 1e-6


def overhang_threshold(angle: float) -> float:
    """The `t` of "a surface overhangs where n·d < −t" for an allowed overhang `angle`: a
    face exactly at the limit prints without support (a 45° chamfer under a 45° rule),
    which rounding decided before (branch45's 45° underside: n·d = −0.7071067811865476
    against −sin 45° = −0.7071067811865475, 50 mm² of overhang)."""
    return math.sin(angle) + ROUNDING_SLACK


@dataclass
class OverhangReport:
    """Overhang area (mm²) of one solid in one direction, with the faces that contribute."""

    direction: np.ndarray
    angle: float
    area: float
    faces: list[tuple[int, float]] = field(default_factory=list)
    #: curved faces that overhang but are laid on the bed (`surface_mesh.BED_BAND`)
    laid: list[int] = field(default_factory=list)

    def to_dict(self) -> dict:
        return {"direction": [float(c) for c in self.direction],
                "angle_deg": math.degrees(self.angle), "area": self.area,
                "faces": [{"face": f"Face{i + 1}", "area": a} for i, a in self.faces]}


def _direction(direction: Sequence[float]) -> np.ndarray:
    d = np.asarray(direction, dtype=float).reshape(-1)
    if d.shape != (3,) or not np.all(np.isfinite(d)) or np.linalg.norm(d) < ZERO_LENGTH:
        raise PlanError(f"build direction must be a non-zero 3-vector, got {list(np.ravel(direction))!r}")
    return d / np.linalg.norm(d)


def check_angle(angle: float) -> float:
    if not (math.isfinite(angle) and 0.0 <= angle < math.pi / 2):
        raise PlanError(f"allowed overhang angle must be in [0°, 90°), got {math.degrees(angle):g}°")
    return float(angle)


def lowest_level(shape, d: np.ndarray) -> float:
    """Lowest height of the shape's vertices along d (planar bottoms are bounded by vertices;
    curved bottoms do not rest on the bed flat anyway)."""
    return min(vertex_heights(shape, d))


#: A part stands on the bed only on a flat face at least this large (mm²): a vertex or an
#: edge gives no adhesion (a cube balanced on a corner is support-free but not printable).
MIN_BASE_AREA = 20.0


def base_area(shape, d: np.ndarray) -> float:
    """Area (mm²) of the shape's planar faces lying flat on the bed when built along `d`:
    facing straight down at the shape's lowest level."""
    low = lowest_level(shape, d)
    table = _planar_table(shape)
    if not len(table.indices):
        return 0.0
    all_faces = faces_of(shape)
    area = 0.0
    for index in table.indices[table.normals @ d < -1.0 + PARALLEL_COS_SLACK]:
        face = all_faces[index]
        if abs(float(vertex_points(face)[0] @ d) - low) < ON_PLANE_TOLERANCE:
            area += float(face.Area)
    return area


def _bed_level(shape, d: np.ndarray, low: float, deflection: float) -> float:
    """The shape's lowest point along d: its lowest vertex (`low`) or a curved face's lowest
    mesh node (on the surface), where a round bottom reaches lower (a sphere's lowest vertex
    along X is its centre's level)."""
    lowest = low
    for face in faces_of(shape):
        if plane_normal(face) is None:
            part = face_part(face, deflection)
            if part is not None and len(part.points):
                lowest = min(lowest, float((part.points @ d).min()))
    return lowest


def overhang_report(shape, direction: Sequence[float], angle: float = DEFAULT_OVERHANG_ANGLE,
                    base_faces: Sequence = (), on_bed: bool = True) -> OverhangReport:
    """Area of `shape`'s faces overhanging more than `angle` when built along `direction`.

    Args:
        shape: a solid (or compound) in the part's frame.
        direction: build direction (layers stack along it).
        angle: allowed overhang from the build direction (rad).
        base_faces: planar faces the shape is built on (its parent's split faces); the part of a
            face covered by them is not overhang.
        on_bed: also exclude faces lying on the lowest plane (the build plate), and curved
            or sloping faces laid on it (`surface_mesh.BED_BAND`; the report lists them).
    """
    d = _direction(direction)
    threshold = overhang_threshold(check_angle(angle))
    low = lowest_level(shape, d) if on_bed else None
    deflection = mesh_deflection(shape)
    mesh_faces(shape, deflection)
    bed: list[float] = []       # the bed's level, read once a face may be laid on it

    def bed_level() -> float:
        if not bed:
            bed.append(_bed_level(shape, d, low, deflection))
        return bed[0]

    table = _planar_table(shape)
    all_faces = faces_of(shape)
    areas: dict[int, float] = {}
    laid = []
    # Only the planar faces facing down are looked at one by one (a gear's 400 flat flanks,
    # scanned along 30 directions, cost 0.85 s of its plan choice face by face).
    down = table.normals @ d < -threshold
    near = down & (table.near_bed(d, low) if low is not None and not base_faces
                   else np.ones(len(down), dtype=bool))
    for row in np.flatnonzero(down):
        index = int(table.indices[row])
        face = all_faces[index]
        areas[index] = float(face.Area) - (_supported_area(
            face, table.normals[row], d, low, None if low is None else bed_level,
            base_faces) if near[row] else 0.0)
    for index in table.curved:
        part = face_part(all_faces[index], deflection)
        area = 0.0 if part is None else part.below(d, threshold)
        if (low is not None and area > NEGLIGIBLE_AREA
                and part.laid_on_bed(d, threshold, bed_level, low)):
            area = 0.0
            laid.append(index)
        areas[index] = area
    faces = [(index, areas[index]) for index in sorted(areas) if areas[index] > NEGLIGIBLE_AREA]
    return OverhangReport(direction=d, angle=angle, area=float(sum(a for _, a in faces)),
                          faces=faces, laid=laid)


@dataclass(frozen=True)
class _PlanarTable:
    """A shape's faces sorted once for overhang scans: the planar ones' indices and outward
    normals (one row each), and the indices of the others."""

    indices: np.ndarray
    normals: np.ndarray
    curved: list[int]
    #: every planar face's vertex points, one face after another, and where each begins
    vertices: np.ndarray
    starts: np.ndarray

    def near_bed(self, d: np.ndarray, low: float) -> np.ndarray:
        """Per planar face, whether its top lies within the bed band (and rounding) of the
        lowest level `low`: only such a face can rest on the bed (`_supported_area`)."""
        if not len(self.indices):
            return np.zeros(0, dtype=bool)
        top = np.maximum.reduceat(self.vertices @ d, self.starts)
        return top - low <= BED_BAND + NEAR_BED_SLACK


#: How far beyond BED_BAND (mm) a face's top vertex may seem from the lowest level and
#: still be measured one by one: the heights of one product of all vertices may differ from
#: a face's own in the last bits.
NEAR_BED_SLACK = 1e-6

#: Per shape (oriented: a face's normal follows its orientation), its `_PlanarTable`.
_TABLES: ShapeCache[_PlanarTable] = ShapeCache(limit=4096, oriented=True)


def _planar_table(shape) -> _PlanarTable:
    def build() -> _PlanarTable:
        faces = faces_of(shape)
        normals = [plane_normal(face) for face in faces]
        indices = np.array([i for i, n in enumerate(normals) if n is not None], dtype=int)
        curved = [i for i, n in enumerate(normals) if n is None]
        points = [vertex_points(faces[i]) for i in indices]
        starts = np.cumsum([0] + [len(p) for p in points[:-1]]).astype(int)
        return _PlanarTable(
            indices, np.array([normals[i] for i in indices]) if len(indices) else np.zeros((0, 3)),
            curved, np.array([p for face in points for p in face]) if points else np.zeros((0, 3)),
            starts)

    return _TABLES.get((shape,), build)


#: Overhang areas of whole shapes (no base faces), by shape identity and (direction, angle,
#: on the bed): the search scans the part's candidate directions, and the decomposition
#: scans its placed copy's again (Pump_Nut: 49 of 79 scans repeated, 0.09 s of its choice).
_AREAS: ShapeCache[dict] = ShapeCache(limit=4096, oriented=True)


def overhang_area(shape, direction: Sequence[float], angle: float = DEFAULT_OVERHANG_ANGLE,
                  base_faces: Sequence = (), on_bed: bool = True) -> float:
    """Total overhang area (mm²); see `overhang_report`."""
    if base_faces:
        return overhang_report(shape, direction, angle, base_faces, on_bed).area
    key = (tuple(float(c) for c in np.ravel(direction)), float(angle), bool(on_bed))
    return _AREAS.get_keyed((shape,), key, lambda: overhang_report(
        shape, direction, angle, base_faces, on_bed).area)


def share_overhang_areas(original, copy) -> None:
    """Give `copy`, made of `original` and not moved (the same faces, in the same order, with
    the same meshes: `surface_mesh.share_face_parts`), the overhang areas measured of it
    and of each of its solids (the search scans the solid of a one-solid compound)."""
    for shape, twin in [(original, copy)] + list(zip(original.Solids, copy.Solids)):
        known = _AREAS.peek((shape,))
        if known is not None:
            _AREAS.get((twin,), lambda known=known: known)


def _supported_area(face, normal: np.ndarray, d: np.ndarray, low: float | None,
                    bed_level: Callable[[], float] | None, base_faces: Sequence) -> float:
    """How much of a downward planar face rests on the bed or on the base faces: all of one
    on the bed, or of a sloping one laid on it (`surface_mesh.laid_at`, at its top)."""
    level = float(vertex_points(face)[0] @ d)
    if low is not None and abs(normal @ d + 1.0) < PARALLEL_COS_SLACK and abs(level - low) < ON_PLANE_TOLERANCE:
        return float(face.Area)
    if bed_level is not None and abs(normal @ d + 1.0) >= PARALLEL_COS_SLACK:
        top = max(vertex_heights(face, d))
        # The bed is not above the lowest vertex: a top more than the band over that is
        # not laid, whatever the bed's level (reading it costs a pass over the mesh).
        if top - low <= BED_BAND and laid_at(top - bed_level(), float(-(normal @ d)), PLANE_RUN):
            return float(face.Area)
    supported = 0.0
    for base in base_faces:
        base_normal = plane_normal(base)
        if base_normal is None or abs(abs(base_normal @ normal) - 1.0) > PARALLEL_COS_SLACK:
            continue
        if abs(float(vertex_points(base)[0] @ normal)
               - float(vertex_points(face)[0] @ normal)) > ON_PLANE_TOLERANCE:
            continue
        if not face.BoundBox.intersect(base.BoundBox):
            continue
        supported += float(face.common(base).Area)
    return min(supported, float(face.Area))


#: Candidate single directions for the whole part: the six axis directions.
AXIS_DIRECTIONS = tuple(np.array(v, dtype=float) for v in
                        ((0, 0, 1), (0, 0, -1), (1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0)))


#: The 26 directions of a cube's faces, edges and corners (unit), axis directions first so
#: ties keep the simplest turn.
CUBE_DIRECTIONS = AXIS_DIRECTIONS + tuple(
    np.array(v, dtype=float) / np.linalg.norm(v)
    for v in ((x, y, z) for x in (-1, 0, 1) for y in (-1, 0, 1) for z in (-1, 0, 1))
    if sum(map(abs, v)) > 1)
#: Planar faces whose outward normal may be put down on the bed ("place on face"): the
#: largest few, as a planar slicer offers them.
PLACE_ON_FACES = 6


def orientation_candidates(shape, largest: int = PLACE_ON_FACES) -> list[np.ndarray]:
    """Build directions to try for the whole part: the cube's 26 and, for each of its
    `largest` planar faces, the direction that stands the part on that face (the face's
    outward normal pointing down), without repeats."""
    candidates = list(CUBE_DIRECTIONS)
    planar = sorted((f for f in faces_of(shape) if plane_normal(f) is not None),
                    key=lambda f: f.Area, reverse=True)[:largest]
    for face in planar:
        normal = plane_normal(face)
        # normalised again, as when it was read here: the candidates keep their bits
        direction = -normal / np.linalg.norm(normal)
        if all(float(direction @ c) < 1.0 - PARALLEL_COS_SLACK for c in candidates):
            candidates.append(direction)
    return candidates


#: A part's first layer is read this far (mm) above its lowest point: the middle of a
#: default 0.2 mm first layer, where the slicer cuts it.
FIRST_LAYER_PROBE = 0.1


#: First-layer areas by shape identity and direction (`footprint_area`).
_FOOTPRINTS: ShapeCache[dict] = ShapeCache(limit=1024, oriented=False)


def footprint_area(shape, d: np.ndarray) -> float:
    """Area (mm²) of the shape's first layer built along `d` (its exact section
    FIRST_LAYER_PROBE above its lowest point): what it rests on, flat face or not."""
    from freecad_conformal.geometry.sections import lowest_along, planar_sections

    d = _direction(d)

    def area() -> float:
        stack = planar_sections(shape, d, heights=[lowest_along(shape, d) + FIRST_LAYER_PROBE])
        return float(stack.layers[0].area)

    return _FOOTPRINTS.get_keyed((shape,), tuple(float(c) for c in d), area)


def stands(shape, d: np.ndarray) -> bool:
    """Whether the part built along `d` stands on the bed: on a flat face (`base_area`) or
    a first layer (`footprint_area`) of MIN_BASE_AREA at least. A ring on its edge or an
    arm on the round end of a boss rests on a line: a first layer of a few mm² under a
    part 50-150 mm tall, which tips or peels off."""
    return base_area(shape, d) >= MIN_BASE_AREA or footprint_area(shape, d) >= MIN_BASE_AREA


def standing_directions(shape, directions: Sequence[np.ndarray]) -> list[np.ndarray]:
    """Those of `directions` in which the part stands on a flat face (MIN_BASE_AREA)."""
    return [d for d in directions if base_area(shape, d) >= MIN_BASE_AREA]


def best_single_direction(shape, angle: float = DEFAULT_OVERHANG_ANGLE,
                          candidates: Sequence[np.ndarray] | None = None,
                          tie: float = NEGLIGIBLE_AREA) -> tuple[np.ndarray, float]:
    """The candidate direction with the least overhang for the whole part, and that area;
    a later candidate replaces an earlier one only when it leaves more than `tie` (mm²)
    less (the callers that weigh a turn pass the overhang measure's noise: the first
    candidate, +Z, is the part as placed). Candidates default to the six axes,
    then the rest of `orientation_candidates` in which the part stands on a flat face: the
    axes alone missed a part's own directions once it was modelled turned (see
    decomposition/decompose._turned_further). The part must stand on the bed that way
    (`stands`), unless it stands in none of them."""
    if candidates is None:
        others = orientation_candidates(shape)[len(AXIS_DIRECTIONS):]
        candidates = [*AXIS_DIRECTIONS, *standing_directions(shape, others)]
    # The part must stand (`stands`): the best that does, or where none does (a ball) the
    # best of all. Only the winners are read for their footprint (an exact section, 0.1 s
    # on CrankArm's arm).
    left = list(candidates)
    while left:
        best = _least_overhang(shape, angle, left, tie)
        if stands(shape, best[0]):
            return best
        left = [c for c in left if not np.array_equal(np.asarray(c, dtype=float), best[0])]
    return _least_overhang(shape, angle, candidates, tie)


def _least_overhang(shape, angle: float, candidates: Sequence[np.ndarray],
                    tie: float) -> tuple[np.ndarray, float]:
    best = None
    for candidate in candidates:
        area = overhang_area(shape, candidate, angle)
        if best is None or area < best[1] - tie:
            best = (np.asarray(candidate, dtype=float), area)
    return best
