"""Trial cuts on a piece's mesh (geometry/surface_mesh.py), for ranking the decomposition's
candidate cuts without Booleans (decomposition/decompose.py).

A plane's interior regions are the points with material on both sides of it: the mesh's
sections just above and just below the plane, intersected (shapely). Cutting along one
region R splits the surface where it crosses the plane inside R and nowhere else: triangles
crossing the plane are split there, pieces sharing an edge are joined unless the edge lies
in the plane within R, and the connected parts are the trial's pieces. Their overhang is
read from the exact corner normals as `FacePart.below` does (geometry/surface_mesh.py); the part's exact cut then
only has to be made for the cut that wins.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import reduce
from typing import Callable

import numpy as np
import shapely
from shapely.geometry import LineString, Polygon

from freecad_conformal.decomposition.mesh_topology import along, paired_edges, topology
from freecad_conformal.geometry.components import connected_labels
from freecad_conformal.geometry.surface_mesh import SurfaceMesh, below_fraction
from freecad_conformal.tolerances import PARALLEL_COS_SLACK

#: A node within this (mm) of the plane lies on it: OCC's confusion distance; nodes on a
#: planar face in the plane sit there to ~1e-12.
ON_PLANE = 1e-7

#: The sections read as "just above" and "just below" the plane are this far (mm) from it:
#: beyond ON_PLANE, and far below any wall's horizontal run at the mesh's angles.
SECTION_OFFSET = 1e-6

#: An edge in the plane lies in the region when within this (mm) of it: the region's outline
#: comes from sections SECTION_OFFSET away, which moves a wall at 1° to the plane by 6e-5.
IN_REGION = 1e-4

#: Regions and pieces with less area than this fraction of the piece's surface are slivers
#: of the offset sections or of split triangles (mm² relative).
SLIVER_AREA = 1e-9


@dataclass
class MeshRegion:
    """One interior region of a plane, as a polygon in the plane's frame (u, v)."""

    point: np.ndarray
    normal: np.ndarray
    u: np.ndarray
    v: np.ndarray
    polygon: Polygon
    face_index: int | None = None

    def to_3d(self, xy: np.ndarray) -> np.ndarray:
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        return self.point + xy[:, :1] * self.u + xy[:, 1:] * self.v

    def boundary_points(self) -> np.ndarray:
        return self.to_3d(np.asarray(self.polygon.exterior.coords))

    def inner_point(self) -> np.ndarray:
        p = self.polygon.representative_point()
        return self.to_3d([p.x, p.y])[0]


@dataclass
class MeshTrial:
    """Overhang (mm²) left by one trial cut: the kept piece's, and each child's with its
    build direction."""

    total: float
    keeper: float
    children: list[tuple[np.ndarray, float]]
    #: () -> ((corners (T, 3, 3), face index (T,)) of the kept piece's triangles, the same
    #: of the child's): the parts' surfaces for a collision check, made only when asked
    triangles: Callable[[], tuple[tuple[np.ndarray, np.ndarray],
                                  tuple[np.ndarray, np.ndarray]]] | None = None


def mesh_overhang(mesh: SurfaceMesh, direction: np.ndarray, threshold: float,
                  factor: np.ndarray) -> float:
    """The uncut mesh's overhang in `direction` (as a trial reads it, for comparing)."""
    area = topology(mesh).area
    return _overhang(area, mesh.normals, np.ones(len(area), bool), direction, threshold,
                     factor[mesh.faces])


def plane_frame(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors completing `normal` to a right-handed frame."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(normal[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(normal, helper)
    u /= np.linalg.norm(u)
    return u, np.cross(normal, u)


def mesh_regions(mesh: SurfaceMesh, point: np.ndarray, normal: np.ndarray,
                 touching: list[tuple[int, list[np.ndarray]]] | None = None) -> list[MeshRegion]:
    """The plane's interior regions; with `touching` [(face index, [edge points (K, 3)])],
    only those touching one of the edges, credited to the first face whose edge they touch
    (as `splitting_faces.plane_regions`)."""
    u, v = plane_frame(normal)
    s = (mesh.points - point) @ normal
    above = _section(mesh, s - SECTION_OFFSET, point, u, v)
    below = _section(mesh, s + SECTION_OFFSET, point, u, v)
    inside = above.intersection(below)
    polygons = [g for g in getattr(inside, "geoms", [inside]) if isinstance(g, Polygon)]
    minimum = SLIVER_AREA * max(float(np.sum(topology(mesh).area)), 1.0)
    regions = []
    for polygon in polygons:
        if polygon.area <= minimum:
            continue
        region = MeshRegion(point, normal, u, v, polygon)
        if touching is None:
            regions.append(region)
            continue
        reach = 2.0 * mesh.deflection + IN_REGION
        for index, edges in touching:
            if any(polygon.distance(_line(e, point, u, v)) < reach for e in edges):
                region.face_index = index
                regions.append(region)
                break
    return regions


def _line(points: np.ndarray, origin: np.ndarray, u: np.ndarray, v: np.ndarray):
    rel = points - origin
    xy = np.column_stack([rel @ u, rel @ v])
    return LineString(xy) if len(xy) > 1 else shapely.Point(xy[0])


def _straddling(side: np.ndarray, triangles: np.ndarray):
    """Triangles with nodes on both sides, and their nodes (a, b, c) rotated so a is alone."""
    sides = side[triangles]
    count = sides.sum(axis=1)
    crossing = np.nonzero((count == 1) | (count == 2))[0]
    lone = np.where(count[crossing] == 1, np.argmax(sides[crossing], axis=1),
                    np.argmin(sides[crossing], axis=1))
    order = (lone[:, None] + np.arange(3)[None, :]) % 3
    abc = np.take_along_axis(triangles[crossing], order, axis=1)
    return crossing, order, abc


def _cut_points(mesh: SurfaceMesh, s: np.ndarray, abc: np.ndarray):
    """Where the edges a–b and c–a of the straddling triangles `abc` (a alone) meet s = 0:
    one point per mesh edge (both triangles on it read the same), and per triangle the
    index of its point on a–b and on c–a."""
    n = len(mesh.points)
    a, b, c = abc[:, 0], abc[:, 1], abc[:, 2]
    on_ab = np.minimum(a, b) * n + np.maximum(a, b)
    on_ca = np.minimum(c, a) * n + np.maximum(c, a)
    keys, inverse = np.unique(np.concatenate([on_ab, on_ca]), return_inverse=True)
    i, j = keys // n, keys % n
    t = s[i] / (s[i] - s[j])
    points = mesh.points[i] + t[:, None] * (mesh.points[j] - mesh.points[i])
    return points, inverse[:len(abc)], inverse[len(abc):]


def _section(mesh: SurfaceMesh, s: np.ndarray, origin, u, v):
    """The material's section where s = 0 (no node exactly there), as shapely geometry."""
    side = s > 0
    _, _, abc = _straddling(side, mesh.triangles)
    if not len(abc):
        return Polygon()
    xyz, first, second = _cut_points(mesh, s, abc)
    xy = np.column_stack([(xyz - origin) @ u, (xyz - origin) @ v])
    neighbours: dict[int, list[int]] = {}
    for p, q in zip(first.tolist(), second.tolist()):
        neighbours.setdefault(p, []).append(q)
        neighbours.setdefault(q, []).append(p)
    rings = []
    seen: set[int] = set()
    for begin in neighbours:
        if begin in seen:
            continue
        ring, previous, current = [begin], None, begin
        seen.add(begin)
        while True:
            options = [k for k in neighbours[current] if k != previous]
            following = options[0] if options else None
            if following is None or following == begin or following in seen:
                break
            ring.append(following)
            seen.add(following)
            previous, current = current, following
        if len(ring) >= 3:
            polygon = Polygon(xy[ring])
            rings.append(polygon if polygon.is_valid else polygon.buffer(0))
    if not rings:
        return Polygon()
    # Rings of a closed surface's section do not cross: even-odd nesting is the material.
    return reduce(lambda a, b: a.symmetric_difference(b), sorted(rings, key=lambda r: -r.area))


def mesh_trial(mesh: SurfaceMesh, region: MeshRegion, direction: np.ndarray, threshold: float,
               keeper_factor: np.ndarray, low: float, level_tolerance: float,
               same_direction: float, min_thickness: float = 0.0,
               on_bed: bool = False) -> MeshTrial | None:
    """The overhang left by cutting the mesh along `region`, or None when the cut does not
    leave one piece on the base and children built away from it.

    Args:
        direction: the piece's build direction; the kept piece is the one part with a vertex
            at its lowest level `low` (within `level_tolerance`) and, unless the piece
            stands on the bed, holding one of its planar faces there facing down, if it has
            any.
        threshold: `geometry/overhang.overhang_threshold` of the allowed overhang angle.
        keeper_factor: per face of the piece, the share of its overhang the piece has in
            `direction` (below 1 where a planar face rests on the bed or the base).
        same_direction: children built within this angle (rad) of `direction` are no use.
        min_thickness: a piece spanning less (mm) along its build direction is a sliver:
            no use either (as `planner.try_cut` judges the exact cut).
        on_bed: the piece stands on the bed (a root), where any part reaching the bed's
            level is on it, by a face or an edge alike (as `planner.try_cut` judges it: a
            part touching the bed along an edge cannot be built later from a cut face,
            the nozzle beside it would meet the platform).
    """
    p, n = region.point, region.normal
    s = (mesh.points - p) @ n
    side = s > ON_PLANE
    split = _split(mesh, s, side)
    label = _parts(mesh, split, region, s, side)
    if label is None:
        return None
    pieces = split.pieces
    above, below = label[pieces], label[pieces + 1]
    whole, crossing = split.whole, split.crossing
    topo = topology(mesh)
    # Sub-triangles in one order throughout (the whole triangles, then the crossing ones'
    # three parts), so that every sum adds the same numbers in the same order.
    component = np.concatenate([label[whole], label[split.sub_piece]])
    area = np.concatenate([topo.area[whole],
                           split.sub_area * mesh.scale[split.sub_source]])
    total_area = np.bincount(component, weights=area, minlength=int(label.max()) + 1)
    minimum = SLIVER_AREA * max(float(total_area.sum()), 1.0)
    sides = {above: True, below: False}
    if any(total_area[k] > minimum and k not in sides for k in range(len(total_area))):
        return None  # a part of the surface bounded by neither side: not a solid's mesh
    per = along(mesh, direction, threshold, keeper_factor, low, level_tolerance)
    sub_levels = split.corners[split.sub_tri] @ direction
    sub_normals = split.sub_normals
    sub_base = (mesh.planar[split.sub_source]
                & (sub_normals[:, 0] @ direction < -1.0 + PARALLEL_COS_SLACK)
                & (np.abs(sub_levels.max(axis=1) - low) <= level_tolerance))
    # As `support.lowest_level`, a part's lowest level is that of its vertices (the
    # shape's; the cut's own are left out).
    reach = np.full(len(total_area), np.inf)
    kept = ~np.isin(topo.vertex_triangles, crossing, assume_unique=True) if len(crossing) \
        else np.ones(len(topo.vertex_triangles), bool)
    np.minimum.at(reach, label[topo.vertex_triangles[kept]], per.vertex_level[kept])
    is_vertex = np.zeros(len(split.corners), bool)
    is_vertex[mesh.vertices] = True
    sub_vertex = np.where(is_vertex[split.sub_tri], sub_levels, np.inf).min(axis=1)
    np.minimum.at(reach, label[split.sub_piece], sub_vertex)
    holds = np.zeros(len(total_area), bool)
    base_whole = whole[per.base[whole]]
    holds[label[base_whole]] = True
    holds[label[split.sub_piece[sub_base]]] = True
    any_base = len(base_whole) > 0 or bool(sub_base.any())
    at_level = {k: bool(reach[k] <= low + level_tolerance) for k in sides}
    if on_bed:
        # The exact cut gives both parts the cut face's own vertices: where it reaches the
        # bed (a ramp cut off at its foot), or where a part holds some of the bed face
        # though none of the solid's vertices (half of a round foot), the part is on it.
        if float((region.boundary_points() @ direction).min()) <= low + level_tolerance:
            return None
        on_base = [k for k in sides if at_level[k] or holds[k]]
    else:
        on_base = [k for k in sides if at_level[k] and (holds[k] or not any_base)]
    if len(on_base) != 1:
        return None
    keeper = on_base[0]
    other = next(k for k in sides if k != keeper)
    child = n if sides[other] else -n
    if math.acos(float(np.clip(child @ direction, -1.0, 1.0))) < same_direction:
        return None
    if min_thickness > 0 and (
            _span(mesh, split, component == keeper, direction) < min_thickness
            or _span(mesh, split, component == other, child) < min_thickness):
        return None
    in_keeper = component == keeper
    whole_count = len(whole)
    sub_share = area[whole_count:] * below_fraction(sub_normals @ direction + threshold)
    sub_share = sub_share * keeper_factor[mesh.faces[split.sub_source]]
    keeper_area = float(np.concatenate([per.keeper_overhang[whole][in_keeper[:whole_count]],
                                        sub_share[in_keeper[whole_count:]]]).sum())
    if child @ direction < -threshold:
        keeper_area += float(region.polygon.area)  # the kept piece's cut face
    in_child = component == other
    child_normals = np.concatenate([mesh.normals[whole[in_child[:whole_count]]],
                                    sub_normals[in_child[whole_count:]]])
    child_area = float((area[in_child] * below_fraction(child_normals @ child + threshold)).sum())

    def triangles():
        corners = np.concatenate([mesh.points[mesh.triangles[whole]],
                                  split.corners[split.sub_tri]])
        faces = np.concatenate([mesh.faces[whole], mesh.faces[split.sub_source]])
        return (corners[in_keeper], faces[in_keeper]), (corners[in_child], faces[in_child])
    return MeshTrial(keeper_area + child_area, keeper_area, [(child, child_area)], triangles)


def _overhang(area, normals, mask, d, threshold, factor) -> float:
    """Σ area where n·d < −threshold over the masked triangles, n linear between the
    corners and the triangle clipped at the limit (as `FacePart.below`)."""
    weights = area[mask] * below_fraction(normals[mask] @ d + threshold)
    if not np.isscalar(factor):
        weights = weights * factor[mask]
    return float(weights.sum())


def _span(mesh: SurfaceMesh, split: "_Split", mask: np.ndarray, d: np.ndarray) -> float:
    """Extent along `d` of the corners of the sub-triangles in `mask` (whole ones first, as
    `mesh_trial` orders them; 0 for none)."""
    whole_count = len(split.whole)
    corners = np.concatenate([mesh.triangles[split.whole[mask[:whole_count]]].ravel(),
                              split.sub_tri[mask[whole_count:]].ravel()])
    if not len(corners):
        return 0.0
    levels = (split.corners @ d)[corners]   # a level per node, then gathered: the same values
    return float(levels.max() - levels.min())


@dataclass
class _Split:
    """The mesh's triangles split at the plane: `corners` (nodes, then cut points); the
    triangles on one side (`whole`, each its own piece) and those crossing it (`crossing`),
    each split into three sub-triangles `sub_tri` (into corners; the lone corner's, then
    the two of the other side) with corner `sub_normals`, their `sub_source` triangle and
    `sub_piece` (the lone corner's part is piece M + k, the other part keeps the triangle's
    index); `pieces` in all (M + K)."""

    pieces: int
    corners: np.ndarray
    whole: np.ndarray
    crossing: np.ndarray
    lone_above: np.ndarray
    sub_tri: np.ndarray
    sub_normals: np.ndarray
    sub_source: np.ndarray
    sub_piece: np.ndarray
    sub_area: np.ndarray


def _split(mesh: SurfaceMesh, s: np.ndarray, side: np.ndarray) -> _Split:
    tri = mesh.triangles
    m, n = len(tri), len(mesh.points)
    crossing, order, abc = _straddling(side, tri)
    is_whole = np.ones(m, bool)
    is_whole[crossing] = False
    a, b, c = abc[:, 0], abc[:, 1], abc[:, 2]
    cut_points, on_ab, on_ca = _cut_points(mesh, s, abc)
    corners = np.concatenate([mesh.points, cut_points])
    x_ab, x_ca = n + on_ab, n + on_ca
    nrm = np.take_along_axis(mesh.normals[crossing], order[:, :, None], axis=1)
    na, nb, nc = nrm[:, 0], nrm[:, 1], nrm[:, 2]
    t_ab = (s[a] / (s[a] - s[b]))[:, None]
    t_ca = (s[a] / (s[a] - s[c]))[:, None]
    n_ab = _unit(na + t_ab * (nb - na))
    n_ca = _unit(na + t_ca * (nc - na))
    k = len(crossing)
    sub_tri = np.concatenate([np.column_stack([a, x_ab, x_ca]), np.column_stack([x_ab, b, c]),
                              np.column_stack([x_ab, c, x_ca])])
    sub_normals = np.concatenate([np.stack([na, n_ab, n_ca], axis=1),
                                  np.stack([n_ab, nb, nc], axis=1),
                                  np.stack([n_ab, nc, n_ca], axis=1)])
    pts = corners[sub_tri]
    sub_area = 0.5 * np.linalg.norm(np.cross(pts[:, 1] - pts[:, 0], pts[:, 2] - pts[:, 0]), axis=1)
    return _Split(m + k, corners, np.flatnonzero(is_whole), crossing, side[a], sub_tri,
                  sub_normals, np.tile(crossing, 3),
                  np.concatenate([m + np.arange(k), crossing, crossing]), sub_area)


def _parts(mesh: SurfaceMesh, split: _Split, region: MeshRegion, s: np.ndarray,
           side: np.ndarray) -> np.ndarray | None:
    """Per piece, and for the two nodes standing for the region's two faces (pieces, pieces
    + 1), the label of the part of the surface it belongs to; None when both faces of the
    region fall in one part (the cut does not separate the surface there)."""
    m, pieces = len(mesh.triangles), split.pieces
    upper = _piece_sides(mesh, split, s, side, region.normal)
    on_plane = np.concatenate([np.abs(s) <= ON_PLANE,
                               np.ones(len(split.corners) - len(mesh.points), bool)])
    topo = topology(mesh)
    is_whole = np.zeros(m, bool)
    is_whole[split.whole] = True
    # Triangles on one edge, unless both cross the plane: a crossing triangle meets a whole
    # one on its edge that does not cross the plane, which the part away from its lone
    # corner holds (piece number = triangle number).
    kept = is_whole[topo.pairs[:, 0]] | is_whole[topo.pairs[:, 1]]
    first, second = topo.pairs[kept, 0], topo.pairs[kept, 1]
    i, j = topo.nodes[kept, 0], topo.nodes[kept, 1]
    # Edges of the crossing triangles' parts, paired by their nodes (cut points included).
    sub_pairs, sub_nodes = paired_edges(split.sub_tri, split.sub_piece, len(split.corners))
    first = np.concatenate([first, sub_pairs[:, 0]])
    second = np.concatenate([second, sub_pairs[:, 1]])
    i = np.concatenate([i, sub_nodes[:, 0]])
    j = np.concatenate([j, sub_nodes[:, 1]])
    # Edges lying in the plane inside the region are where the cut separates the surface,
    # only where the surface passes from one side to the other: a face touching the plane
    # from one side along the region's outline is not cut there.
    flat = on_plane[i] & on_plane[j]
    inside = np.zeros(len(first), bool)
    if flat.any():
        middle = 0.5 * (split.corners[i[flat]] + split.corners[j[flat]]) - region.point
        grown = region.polygon.buffer(IN_REGION)
        shapely.prepare(grown)
        inside[flat] = shapely.intersects_xy(grown, middle @ region.u, middle @ region.v)
    cut = inside & (upper[first] != upper[second])
    joined = ~cut
    # Both sides of the region are faces of the pieces it leaves: every part of the surface
    # it bounds from above is joined through it, and every part below (a pocket under the
    # cut is a separate part of the surface, joined to the rest only by the cut face).
    above_node, below_node = pieces, pieces + 1
    upper_piece = np.where(upper[first[cut]], first[cut], second[cut])
    lower_piece = np.where(upper[first[cut]], second[cut], first[cut])
    rows = np.concatenate([first[joined], upper_piece, lower_piece])
    cols = np.concatenate([second[joined], np.full(len(upper_piece), above_node),
                           np.full(len(lower_piece), below_node)])
    label = connected_labels(pieces + 2, rows, cols)
    return None if label[above_node] == label[below_node] else label


def _piece_sides(mesh: SurfaceMesh, split: _Split, s: np.ndarray, side: np.ndarray,
                 n: np.ndarray) -> np.ndarray:
    """Per piece, whether it lies above the plane. A triangle in the plane (on a planar face
    lying in it) counts on the side its material is."""
    tri = mesh.triangles
    upper = np.zeros(split.pieces, bool)
    whole = split.whole
    upper[whole] = side[tri[whole, 0]]      # a whole triangle's corners are on one side
    on_plane = np.abs(s) <= ON_PLANE
    if on_plane.any():
        flat = whole[on_plane[tri[whole]].all(axis=1)]
        upper[flat] = mesh.normals[flat, 0] @ n < 0
    k = len(split.crossing)
    upper[len(tri) + np.arange(k)] = split.lone_above
    upper[split.crossing] = ~split.lone_above
    return upper


def _unit(v: np.ndarray) -> np.ndarray:
    length = np.linalg.norm(v, axis=1, keepdims=True)
    return v / np.where(length > 0, length, 1.0)
