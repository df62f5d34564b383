"""What the trial cuts on one mesh share (decomposition/mesh_cut.py), computed once per mesh.

A trial splits only the triangles its plane crosses; every other triangle keeps its area,
its neighbours and, for the piece's own build direction, its overhang and its standing on
the base. Sorting all 3M edge keys to pair the triangles again cost every trial on the fan's
130,000-triangle pieces 17 ms (1.2 s of its +Z plan), and reading every triangle's overhang
again as much: here the pairs are found once, and the per-direction values once per
direction.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from freecad_conformal.geometry.surface_mesh import SurfaceMesh, below_fraction
from freecad_conformal.tolerances import PARALLEL_COS_SLACK


@dataclass
class Topology:
    """Per mesh: `pairs` (P, 2), the two triangles on each edge, with the edge's `nodes`
    (P, 2); `area` (M,), each triangle's area as trials read it (chord-scaled); the
    triangles with a corner at a vertex of the shape (`vertex_triangles`, with the
    corners' mask `vertex_corners` (V, 3))."""

    pairs: np.ndarray
    nodes: np.ndarray
    area: np.ndarray
    vertex_triangles: np.ndarray
    vertex_corners: np.ndarray
    along: dict = field(default_factory=dict)


_TOPOLOGY_KEY = "trial topology"


def topology(mesh: SurfaceMesh) -> Topology:
    """The mesh's topology (made on first use, kept with the mesh)."""
    known = mesh.derived.get(_TOPOLOGY_KEY)
    if known is None:
        known = mesh.derived[_TOPOLOGY_KEY] = _topology(mesh)
    return known


def paired_edges(triangles: np.ndarray, owner: np.ndarray,
                 count: int) -> tuple[np.ndarray, np.ndarray]:
    """(pairs (P, 2) of the owners of two triangles sharing an edge, that edge's nodes (P, 2))
    for `triangles` (K, 3) into `count` nodes, each owned by `owner[k]`; an edge on one
    triangle only pairs with none."""
    e0 = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    owners = np.tile(owner, 3)
    key = np.minimum(e0[:, 0], e0[:, 1]) * count + np.maximum(e0[:, 0], e0[:, 1])
    order = np.argsort(key, kind="stable")
    keys = key[order]
    same = np.flatnonzero(keys[1:] == keys[:-1])
    return (np.column_stack([owners[order[same]], owners[order[same + 1]]]),
            np.column_stack([keys[same] // count, keys[same] % count]))


def _topology(mesh: SurfaceMesh) -> Topology:
    t = mesh.triangles
    m, n = len(t), len(mesh.points)
    pairs, nodes = paired_edges(t, np.arange(m), n)
    a, b, c = (mesh.points[t[:, k]] for k in range(3))
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1) * mesh.scale
    is_vertex = np.zeros(n, bool)
    is_vertex[mesh.vertices] = True
    corners = is_vertex[t]
    vertex_triangles = np.flatnonzero(corners.any(axis=1))
    return Topology(pairs, nodes, area, vertex_triangles, corners[vertex_triangles])


@dataclass
class Along:
    """Per triangle, for one build direction: the overhang it leaves the kept piece
    (area × share below the limit × the face's keeper factor), whether it is a planar
    face resting on the base level, and the least level of its vertex corners (inf for
    none; only `Topology.vertex_triangles`)."""

    keeper_overhang: np.ndarray
    base: np.ndarray
    vertex_level: np.ndarray


def along(mesh: SurfaceMesh, direction: np.ndarray, threshold: float,
          keeper_factor: np.ndarray, low: float, level_tolerance: float) -> Along:
    """The per-triangle values for a piece built along `direction` (kept per mesh: a piece's
    trials all share them)."""
    topo = topology(mesh)
    key = (direction.tobytes(), threshold, low, level_tolerance)
    known = topo.along.get(key)
    if known is not None and known[0] is keeper_factor:
        return known[1]
    normals = mesh.normals
    share = topo.area * below_fraction(normals @ direction + threshold)
    keeper = share * keeper_factor[mesh.faces]
    levels = mesh.points @ direction
    base = (mesh.planar & (normals[:, 0] @ direction < -1.0 + PARALLEL_COS_SLACK)
            & (np.abs(levels[mesh.triangles].max(axis=1) - low) <= level_tolerance))
    corner_levels = levels[mesh.triangles[topo.vertex_triangles]]
    vertex_level = np.where(topo.vertex_corners, corner_levels, np.inf).min(axis=1) \
        if len(corner_levels) else np.zeros(0)
    value = Along(keeper, base, vertex_level)
    topo.along[key] = (keeper_factor, value)
    return value
