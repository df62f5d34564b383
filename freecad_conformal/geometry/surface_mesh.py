"""A solid's closed triangle mesh with OCC's exact normals at the corners.

The decomposition tries many cuts of one piece and keeps few (decomposition/mesh_cut.py): each
trial on this mesh is a few array operations where the exact one is a section Boolean and a
split. The mesh is the piece's own triangulation: BRepMesh meshes every edge once for both
of its faces (so nodes on shared edges coincide and the mesh is closed), and a face a cut
left alone keeps its triangles, so only new faces are meshed. Other code meshes faces on
copies; when the triangulation is found broken anyway, a fresh copy is meshed whole.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry.face_normals import node_normals, plane_normal
from freecad_conformal.geometry.frames import index_rows, points_array
from freecad_conformal.geometry.rows import find_rows, unique_rows
from freecad_conformal.geometry.shape_access import placement_move
from freecad_conformal.geometry.shape_cache import ShapeCache
from freecad_conformal.geometry.shape_parts import faces as faces_of

#: Linear deflection relative to the shape's bounding-box diagonal: 0.1 % (0.16 mm on
#: CrankArm's 160 mm arm) keeps section outlines well inside the 1e-3 mm² cut decisions'
#: scale once normals are exact at the corners; the 0.1 rad angular deflection FreeCAD's
#: `tessellate` asks of BRepMesh bounds the rest (the same triangles as MeshPart gives at
#: 0.1 rad: the fan's 133,914). 0.2 rad meshes 3-4x faster but reads curved faces' overhang
#: less closely (a direction's worst error, a 0.02 rad mesh taken as exact: 0.16-0.37 % on
#: Pump_Nut, the bottle, CrankArm and the table against 0.03-0.08 %; the connecting rod 2.1
#: against 0.9 %), and gave Pump_Nut another plan (three sub-parts instead of one).
RELATIVE_DEFLECTION = 1e-3

#: Nodes of two faces on a shared edge are merged when equal after rounding to this (mm):
#: BRepMesh places them at one 3D point, so any scale far above 1e-12 and far below the
#: mesh spacing works.
NODE_MERGE = 1e-6


@dataclass
class SurfaceMesh:
    """A closed, outward-oriented triangle mesh of one solid.

    points (N, 3); triangles (M, 3) into points; normals (M, 3, 3), the outward unit normal
    of each triangle's own face at each corner (nodes on an edge have one per face); faces
    (M,), the index in `shape.Faces`; planar (M,), whether that face is a plane; scale (M,),
    the face's exact area over its meshed area (chord error), to apply to areas; vertices,
    the nodes at the shape's vertices (its lowest level is read from them, as
    `overhang.lowest_level` does)."""

    points: np.ndarray
    triangles: np.ndarray
    normals: np.ndarray
    faces: np.ndarray
    planar: np.ndarray
    scale: np.ndarray
    deflection: float
    vertices: np.ndarray
    #: what users of the mesh derive from it once (decomposition/mesh_topology.py)
    derived: dict = field(default_factory=dict, repr=False, compare=False)


_MESHES: ShapeCache[SurfaceMesh | None] = ShapeCache(limit=256, oriented=True)


#: Each shape's deflection, read once: `BoundBox` is read from a triangulation once the
#: shape has one (the swept spring's diagonal shrinks from 64.0 to 51.9 mm once meshed).
_DEFLECTIONS: ShapeCache[float] = ShapeCache(limit=16384, oriented=False)


def mesh_deflection(shape) -> float:
    """The linear deflection for meshing `shape` and the pieces cut from it (mm), from its
    box when first asked (before the orientation scans mesh it: a copy made for the plan
    is given its original's, `share_deflection`)."""
    return _DEFLECTIONS.get((shape,), lambda: max(
        RELATIVE_DEFLECTION * shape.BoundBox.DiagonalLength, 1e-4))


def share_deflection(original, copy) -> None:
    """Give `copy`, made of `original` with its mesh (`Shape.copy(False, True)`), turned or
    not, the original's deflection: its box, read from that mesh, would ask for another,
    and BRepMesh meshed the spring's placed copy again at the finer one (5.1 s of its
    plan choice). The decomposition's trial child, which plans only a copy left in place
    and reads it without a mesh, finds the original's value too."""
    _DEFLECTIONS.get((copy,), lambda: mesh_deflection(original))


def surface_mesh(shape, deflection: float | None = None) -> SurfaceMesh | None:
    """The shape's mesh (the one made first, whatever its deflection; default
    `mesh_deflection(shape)`), or None when BRepMesh's result is not a closed 2-manifold
    (callers then work on the exact shape)."""
    return _MESHES.get((shape,), lambda: _build(shape, deflection or mesh_deflection(shape)))


#: Rigid copies of meshed shapes (`seed_moved_mesh`): the original's mesh and the move (a
#: 4 x 4 matrix), read by `made_mesh` alone: `surface_mesh` of a copy still meshes the copy.
_MOVED: ShapeCache[tuple[SurfaceMesh, np.ndarray]] = ShapeCache(limit=4096, oriented=True)

#: A copy's first vertex must lie this close (mm) to the original's moved by the placements'
#: difference for the copy to be taken as moved only by its placement.
MOVED_VERTEX_SLACK = 1e-6


def seed_moved_mesh(original, moved) -> None:
    """Record that `moved` is `original` given a new placement (copied, turned, translated),
    so that `made_mesh(moved)` is the original's mesh moved, if it has one."""
    mesh = _MESHES.peek((original,))
    if mesh is None:
        return
    matrix = np.array(placement_move(original, moved).A, dtype=float).reshape(4, 4)
    if original.Vertexes:
        before = np.array(tuple(original.Vertexes[0].Point))
        after = np.array(tuple(moved.Vertexes[0].Point))
        if np.linalg.norm(matrix[:3, :3] @ before + matrix[:3, 3] - after) > MOVED_VERTEX_SLACK:
            return
    _MOVED.get((moved,), lambda: (mesh, matrix))


def made_mesh(shape) -> SurfaceMesh | None:
    """The shape's mesh if one was made already, of it or of the shape it is a rigid copy of
    (`seed_moved_mesh`), moved with it; None when none was, or it was not closed. Nothing is
    meshed."""
    mesh = _MESHES.peek((shape,))
    if mesh is not None:
        return mesh
    moved = _MOVED.peek((shape,))
    if moved is None:
        return None
    mesh, matrix = moved
    turn, shift = matrix[:3, :3], matrix[:3, 3]
    return dataclasses.replace(mesh, points=mesh.points @ turn.T + shift,
                               normals=mesh.normals @ turn.T, derived={})


def _build(shape, deflection: float) -> SurfaceMesh | None:
    # The shape's own triangulation first: faces a cut left untouched keep theirs, so
    # BRepMesh meshes only the new faces. Where it meshed again faces whose parts were
    # read before, those parts are stale and the shape's own mesh is whole: its faces are
    # read again (a swept spring's box, and so its deflection, shrinks once it has a mesh:
    # BRepMesh meshed its coil again, and meshing a copy as well cost 3.2 s more). Other
    # code may have re-meshed a face on its own (its edges then no longer match its
    # neighbours'); a fresh copy is meshed whole then.
    shape.tessellate(deflection)
    mesh = _read(shape, deflection)
    if mesh is None:
        dropped = [_FACES.discard((face,)) for face in shape.Faces]
        if any(dropped):
            mesh = _read(shape, deflection)
    if mesh is None:
        copy = shape.copy()
        copy.tessellate(deflection)
        mesh = _read(copy, deflection)
    return mesh


@dataclass
class FacePart:
    """One face's part of a mesh: node points (N, 3), triangles (M, 3) into them, the
    outward unit normal at each corner (M, 3, 3; OCC's exact normal, the plane's for a
    planar face), whether the face is planar, and each triangle's area scaled so they sum
    to the exact Face.Area (the chord error then does not bias a total)."""

    points: np.ndarray
    triangles: np.ndarray
    corner_normals: np.ndarray
    planar: bool
    areas: np.ndarray
    #: exact face area over meshed area
    area_ratio: float

    def below(self, d: np.ndarray, threshold: float) -> float:
        """Area where n·d < −threshold, n taken linear over each triangle between its exact
        corner values and the triangle clipped where it crosses the limit (the cap boundary
        is found to second order instead of to a whole triangle)."""
        if not len(self.areas):
            return 0.0
        return float(self.areas @ below_fraction(self.corner_normals @ d + threshold))

    def laid_on_bed(self, d: np.ndarray, threshold: float, bed: Callable[[], float],
                    above: float) -> bool:
        """Whether all of the face's overhang is laid on the bed at level `bed()` along d
        (see BED_BAND): every corner of its overhanging triangles is, its run from the bed
        read as 2 z cot ψ (z its height, ψ the slope there; exact to first order on a round
        profile, z = r(1 − cos ψ)). `above`: a level the bed is not above (the lowest
        vertex): a corner more than BED_BAND over it settles the answer without `bed()`."""
        down = -(self.corner_normals @ d)
        over = below_fraction(threshold - down) > 0.0
        if not over.any():
            return False
        heights = self.points[self.triangles[over]] @ d
        if heights.max() - above > BED_BAND:
            return False
        return bool(np.all(laid_at(heights - bed(), down[over], ROUND_RUN)))


#: A face whose overhang lies no higher than BED_BAND (mm) above the bed, and reaches out
#: from where it leaves the bed by no more than BED_RUN, is laid on it: the first layer
#: rests on the bed and the next steps out onto the first, as a planar slicer prints it.
#: The lower half of a 1 mm fillet along a part's bottom edges rises 0.29 mm over 0.71 mm:
#: counted as overhang, it left a box rounded on every edge 66.2 mm² "to support" and
#: turned it on its end (200 layers, 36:10, against 75 and 29:59 flat). The band is two
#: default layers, so that the triangles across the fillet's 45° line lie in it. A face
#: is laid whole or not at all: a ball of radius 20 on the bed, whose overhang reaches
#: 5.9 mm up, keeps it all, where triangle by triangle the sliver at its lowest point that
#: passes (1/(2R) high) was laid or not as its mesh fell, 3 mm² apart between two sides.
BED_BAND = 0.4
BED_RUN = 1.0
#: A surface's run from the bed to a height z is z cot ψ times this: 1 on a plane at slope
#: ψ, 2 to first order on a round profile read at its top (z = r(1 − cos ψ)).
PLANE_RUN, ROUND_RUN = 1.0, 2.0


def laid_at(z, down, run: float):
    """Whether a surface point z above the bed, with −n·d = `down` there, is laid on it
    (see BED_BAND): z within the band, its run `run` z cot ψ within BED_RUN (numbers or
    arrays alike)."""
    c = np.clip(down, 0.0, 1.0)
    return (z <= BED_BAND) & (run * z * c <= BED_RUN * np.sqrt(1.0 - c * c))


def below_fraction(g: np.ndarray) -> np.ndarray:
    """Per triangle, the fraction of its area where a function linear over it, with values
    g (K, 3) at its corners, is negative."""
    # No row sort (np.sort axis=1 cost the fan's decomposition 5 s of its 32): the least and
    # greatest corner by min/max, the middle one only where the zero crosses the triangle.
    a, b, c = g[:, 0], g[:, 1], g[:, 2]
    g0, g2 = np.minimum(np.minimum(a, b), c), np.maximum(np.maximum(a, b), c)
    result = (g2 < 0).astype(float)
    crossed = np.flatnonzero((g0 < 0) & (g2 >= 0))
    if len(crossed):
        a, b, c = a[crossed], b[crossed], c[crossed]
        g1 = np.maximum(np.minimum(a, b), np.minimum(np.maximum(a, b), c))
        result[crossed] = _crossed_fraction(g0[crossed], g1, g2[crossed])
    return result


def sorted_below_fraction(g0: np.ndarray, g1: np.ndarray, g2: np.ndarray) -> np.ndarray:
    """`below_fraction` of corner values already in order, g0 <= g1 <= g2 per triangle."""
    result = (g2 < 0).astype(float)
    crossed = np.flatnonzero((g0 < 0) & (g2 >= 0))
    if len(crossed):
        result[crossed] = _crossed_fraction(g0[crossed], g1[crossed], g2[crossed])
    return result


def _crossed_fraction(g0: np.ndarray, g1: np.ndarray, g2: np.ndarray) -> np.ndarray:
    """The fraction below zero of triangles it crosses (g0 < 0 <= g2, in order)."""
    part = np.empty(len(g0))
    one = g1 >= 0   # one corner below: the corner's clipped triangle; else all but one's
    g0o, g1o, g2o = g0[one], g1[one], g2[one]
    part[one] = g0o * g0o / ((g0o - g1o) * (g0o - g2o))
    two = ~one
    g0t, g1t, g2t = g0[two], g1[two], g2[two]
    part[two] = 1 - g2t * g2t / ((g2t - g0t) * (g2t - g1t))
    return part


#: Each face's part of a mesh, by face identity: a cut leaves most faces of a piece (and
#: their triangulations) untouched, and the same pieces are read several times while cuts
#: are compared. A face re-meshed meanwhile leaves a stale part whose edges no longer meet
#: its neighbours': the solid's mesh is then not closed and is made afresh.
_FACES: ShapeCache[FacePart | None] = ShapeCache(limit=8192, oriented=True)


def face_part(face, deflection: float) -> FacePart | None:
    """The face's part of its solid's mesh: the one already made (whatever its deflection),
    else the face's own triangulation at `deflection` (`mesh_deflection` of its solid).
    None for a face BRepMesh gives no triangle."""
    return _FACES.get((face,), lambda: _face_part(face, deflection))


def mesh_faces(shape, deflection: float) -> None:
    """Mesh `shape`'s faces that have no part yet in one BRepMesh call, before they are read
    one by one (`face_part`): meshing a solid whole shares each edge's polygon between its
    two faces, where meshing face by face meshes it again for each (Pump_Nut's 25 faces:
    0.11 s against 0.21 s). Faces already triangulated keep their triangles. Only curved
    faces count, and only they are meshed, as one compound: a plane's overhang is read from
    its normal, and meshing a plate's two faces round its 100 holes took BRepMesh 1.45 s of
    1.6 (their edges are meshed with the curved faces, and a later mesh of the solid meshes
    the planes on them)."""
    curved = [face for face in faces_of(shape)
              if _FACES.peek((face,)) is None and plane_normal(face) is None]
    if curved:
        _, Part = import_freecad()
        Part.makeCompound(curved).tessellate(deflection)


def share_face_parts(original, copy) -> None:
    """Give the faces of `copy`, made of `original` with its mesh (`Shape.copy(False, True)`:
    jobs/placement.turn_up) and not moved, the parts already made of the original's faces:
    the same triangles, points and normals, bit for bit (the sphere's face read again cost
    0.02 s of its 0.2 s plan choice). Should BRepMesh re-mesh such a face, the solid's mesh
    no longer closes and is made afresh (`surface_mesh`)."""
    for face, twin in zip(original.Faces, copy.Faces):
        part = _FACES.peek((face,))
        if part is not None:
            _FACES.get((twin,), lambda part=part: part)


def _face_part(face, deflection: float) -> FacePart | None:
    pts, tris = face.tessellate(deflection)
    if not tris:
        return None
    p = points_array(pts)
    t = index_rows(tris)
    normal = plane_normal(face)
    a, b, c = p[t[:, 0]], p[t[:, 1]], p[t[:, 2]]
    doubled = np.cross(b - a, c - a)
    areas = 0.5 * np.linalg.norm(doubled, axis=1)
    if normal is not None:
        corner = np.broadcast_to(normal, (len(t), 3, 3))
    else:
        corner = _flat_where_strained(node_normals(face, p, t)[t], doubled, areas)
    meshed = float(areas.sum())
    ratio = float(face.Area) / meshed if meshed > 0 else 1.0
    return FacePart(p, t, corner, normal is not None, areas * ratio, ratio)


#: A curved face's triangle whose corner normals stray more than this (rad) from its own
#: plane's normal reads its overhang from that plane instead. BRepMesh (FreeCAD asks for a
#: 0.1 rad angular deflection) bounds how far the normal turns along the edges it splits,
#: not across a triangle: on a lofted blade it kept long triangles reaching from the
#: rounded trailing edge (normals sideways) to the flat of the blade (normals up), and
#: interpolating their corners read 17 % less overhang along -Z than the surface has (729
#: against 879 mm² on the fan's five blades, by a 500 x 500 (u, v) grid on the exact
#: surfaces; their planes read 891). Twice BRepMesh's angle: a triangle of a smooth patch
#: stays within it.
MAX_CORNER_STRAIN = 0.2


def _flat_where_strained(corner: np.ndarray, doubled: np.ndarray,
                         areas: np.ndarray) -> np.ndarray:
    """`corner` normals (M, 3, 3) with each triangle whose corners stray more than
    MAX_CORNER_STRAIN from its plane's normal given that normal at all three corners
    (oriented as its corners; `doubled` are the triangles' unnormalised normals, `areas` half
    their lengths)."""
    flat = doubled / np.maximum(2.0 * areas, 1e-300)[:, None]
    toward = np.einsum("ij,ij->i", flat, corner.sum(axis=1))
    flat = flat * np.where(toward < 0, -1.0, 1.0)[:, None]
    strained = (np.einsum("kij,kj->ki", corner, flat).min(axis=1) < math.cos(MAX_CORNER_STRAIN)) \
        & (areas > 0)
    if not strained.any():
        return corner
    corner = corner.copy()
    corner[strained] = flat[strained, None, :]
    return corner


def _read(shape, deflection: float) -> SurfaceMesh | None:
    """The mesh from the faces' current triangulations, None unless closed and connected."""
    points, triangles, normals, faces, planar, scale = [], [], [], [], [], []
    offset = 0
    for index, face in enumerate(shape.Faces):
        part = face_part(face, deflection)
        if part is None:
            continue
        points.append(part.points)
        triangles.append(part.triangles + offset)
        normals.append(part.corner_normals)
        faces.append(np.full(len(part.triangles), index))
        planar.append(np.full(len(part.triangles), part.planar))
        scale.append(np.full(len(part.triangles), part.area_ratio))
        offset += len(part.points)
    if not triangles:
        return None
    all_points = np.concatenate(points)
    keys = np.round(all_points / NODE_MERGE).astype(np.int64)
    first, inverse = unique_rows(keys)
    tri = inverse[np.concatenate(triangles)]
    corners = np.round(np.array([tuple(v.Point) for v in shape.Vertexes]).reshape(-1, 3)
                       / NODE_MERGE).astype(np.int64)
    vertices = _rows_found(keys[first], corners)
    mesh = SurfaceMesh(all_points[first], tri, np.concatenate(normals),
                       np.concatenate(faces), np.concatenate(planar), np.concatenate(scale),
                       deflection, vertices)
    return mesh if _closed(mesh) and _connected(mesh) else None


def _rows_found(table: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """Indices in `table` (K, 3), rows in the order `unique_rows` sorts them, of each of
    `rows` (J, 3) found there, in their order."""
    at = find_rows(table, rows)
    return at[at >= 0].astype(int)


def _connected(mesh: SurfaceMesh) -> bool:
    """One piece of surface: a solid with a void has two, and a trial cut reads each part of
    the surface as bounded by the cut (decomposition/mesh_cut.py)."""
    from freecad_conformal.geometry.components import connected_labels

    t = mesh.triangles
    labels = connected_labels(len(mesh.points), np.concatenate([t[:, 0], t[:, 1]]),
                              np.concatenate([t[:, 1], t[:, 2]]))
    count = int(labels.max()) + 1 if len(labels) else 0
    return count == 1


def _closed(mesh: SurfaceMesh) -> bool:
    """Every directed edge once and its reverse once: closed, manifold, consistently oriented
    (and outward: the enclosed volume is positive)."""
    t = mesh.triangles
    if np.any((t[:, 0] == t[:, 1]) | (t[:, 1] == t[:, 2]) | (t[:, 2] == t[:, 0])):
        return False
    directed = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    n = len(mesh.points)
    forward = np.sort(directed[:, 0] * n + directed[:, 1])
    if np.any(forward[1:] == forward[:-1]):
        return False
    if not np.array_equal(forward, np.sort(directed[:, 1] * n + directed[:, 0])):
        return False
    a, b, c = (mesh.points[t[:, k]] for k in range(3))
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum()) > 0.0
