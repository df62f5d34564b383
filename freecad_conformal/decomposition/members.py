"""Members leaving a base: the table's legs (METHODS section 4's partition at an area jump).

Section 4 partitions a part where its section area jumps and builds the largest self-
supporting piece first, then the pieces resting on it, each turned so its base rests on what
is built. A table turned over (top on the bed, the one direction its top needs no support)
is one piece for the overhang rule: its legs grow from the underside along the same
direction. Section 4 still makes them separate sub-parts: top first, then each leg on it.

`member_split` does that for a piece no cut can improve: on a plane of a splitting face
(one carrying concave edges, METHODS section 3) normal to the piece's build direction, where
two or more separate regions of material cross the plane — several members leave the piece
there — the piece is cut at all of them at once. The base keeps the build direction; each
member becomes a child built along it, on its own region. The split is kept only if it
leaves no more overhang than the piece had, one member alone is never split off (a
column on a base gains nothing from its own sub-part), and the members must be a narrowing
(under half the section they leave: legs, not the two sides of a screw head's slot).
"""
from __future__ import annotations

import math
from typing import Callable

import numpy as np

from freecad_conformal.geometry.splitting_faces import (candidate_planes, faces_on_plane,
                                                        plane_regions)

#: The plane's normal within this angle (rad) of the build direction: members leave along it.
MEMBER_ANGLE = math.radians(1.0)

#: Fewest separate regions on one plane that make members (one is a column: no split).
MIN_MEMBERS = 2

#: Members are narrower than this fraction of the section they leave (their regions plus
#: the base's faces in the plane facing their way): the table's legs are 0.9 % of its top,
#: a stool's 2.4 %; the two sides of a screw head's slot, 88 % of the head, are no members.
MAX_MEMBER_FRACTION = 0.5

#: The split may add this much overhang (mm², Boolean rounding) and still count as equal.
EQUAL_OVERHANG = 1e-3


def member_split(piece, angle: float, budget: int, cut: Callable):
    """(base piece, member pieces) or None; `cut` is the decomposition's exact split
    (piece, candidate, angle, regions=, same_direction=) -> (total, keeper, children)."""
    d = np.asarray(piece.direction, dtype=float)
    planes = [p for p in candidate_planes(piece.shape, piece.concave())
              if abs(float(p.normal @ d)) > math.cos(MEMBER_ANGLE)]
    # Nearest the base first: members are cut where they leave it.
    planes.sort(key=lambda p: float(p.point @ d))
    for plane in planes:
        if _edge_groups(plane) < MIN_MEMBERS:
            continue  # one connected run of concave edges: at most one member leaves here
        regions = plane_regions(piece.shape, plane)
        if len(regions) < MIN_MEMBERS or len(regions) + 1 > budget:
            continue
        if _member_fraction(piece.shape, plane, regions, d) > MAX_MEMBER_FRACTION:
            continue  # no narrowing: the material goes on (a slotted head), no members
        candidate = regions[0]
        candidate.rule = "member"
        trial = cut(piece, candidate, angle, regions=[c.region for c in regions],
                    same_direction=True)
        if trial is None:
            continue
        total, keeper, children = trial
        if len(children) != len(regions) or total > piece.overhang + EQUAL_OVERHANG:
            continue
        if any(float(child.direction @ d) < math.cos(MEMBER_ANGLE) for child in children):
            continue
        return keeper, children
    return None


def _edge_groups(plane) -> int:
    """Connected runs (sharing vertices) of the concave edges on the plane's faces: each
    member leaving the plane is ringed by its own, so fewer runs than MIN_MEMBERS rule the
    plane out before any Boolean."""
    edges = {id(e.edge): e.edge for _, edge_list in plane.faces for e in edge_list}
    parent = {key: key for key in edges}

    def root(key):
        while parent[key] != key:
            parent[key] = parent[parent[key]]
            key = parent[key]
        return key

    owner: dict[int, list] = {}
    for key, edge in edges.items():
        for vertex in edge.Vertexes:
            for other_vertex, other in owner.get(vertex.hashCode(), []):
                if other_vertex.isSame(vertex):
                    parent[root(key)] = root(other)
            owner.setdefault(vertex.hashCode(), []).append((vertex, key))
    return len({root(key) for key in edges})


def _member_fraction(shape, plane, regions: list, d: np.ndarray) -> float:
    """The members' share of the section they leave: their regions' area over it plus the
    area of the solid's faces in the plane that face along d (the shoulder they rise from)."""
    from freecad_conformal.geometry.face_normals import plane_normal

    members = sum(float(c.region.Area) for c in regions)
    shoulder = sum(float(face.Area) for face in faces_on_plane(shape, plane.point, plane.normal)
                   if float(plane_normal(face) @ d) > 0)
    return members / (members + shoulder) if members + shoulder > 0 else 1.0
