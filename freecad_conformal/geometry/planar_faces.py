"""Section faces on a plane from curve pieces: closed wires, outer loops and holes.

Pieces are chained at the crossing points they share (ids, not coordinates, so no tolerance
decides what joins). Each closed wire gets its area and centroid from one face built on it
alone, whose sign orients the wire; nesting depth tells outer loops from holes, and a face's
area and centroid follow from its loops' without integrating again.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from freecad_conformal.freecad_env import import_freecad

#: A closed section loop enclosing less than this (mm²) is a sliver the Boolean would not
#: return either (it drops faces under tolerances.MIN_SECTION_AREA): leave it to the Boolean.
MIN_LOOP_AREA = 1e-9

#: Relative slack when testing whether one loop's box lies in another's (OCC pads boxes by
#: edge tolerances, differently for lines and B-splines).
BOX_SLACK = 1e-6

#: (edges, first crossing id, last crossing id); ids are None for a whole closed curve.
Piece = tuple[list, "int | None", "int | None"]


class SectionFace(NamedTuple):
    """One section face with its exact area (mm²) and centroid (3,)."""

    face: object
    area: float
    centroid: np.ndarray

    @classmethod
    def of(cls, face) -> "SectionFace":
        return cls(face, float(face.Area), np.array(tuple(face.CenterOfMass)))


def faces_from_pieces(pieces: list[Piece], point_count: int, plane) -> list[SectionFace] | None:
    """Faces bounded by the pieces, or None unless every crossing joins exactly two pieces
    into closed wires."""
    degree = np.zeros(point_count, dtype=int)
    for _, first, last in pieces:
        for pid in (first, last):
            if pid is not None:
                degree[pid] += 1
    if np.any((degree != 0) & (degree != 2)):
        return None
    wires = _chain(pieces)
    if wires is None:
        return None
    return _faces_of_wires(wires, plane)


def _chain(pieces: list[Piece]) -> list | None:
    """Closed wires from pieces joined at their crossing ids."""
    _, Part = import_freecad()
    at_point: dict[int, list[int]] = {}
    for index, (_, first, last) in enumerate(pieces):
        for pid in (first, last):
            if pid is not None:
                at_point.setdefault(pid, []).append(index)
    used = [False] * len(pieces)
    wires = []
    for index, (edges, first, last) in enumerate(pieces):
        if used[index]:
            continue
        used[index] = True
        chain, current = list(edges), last
        while current is not None and current != first:
            following = [i for i in at_point[current] if not used[i]]
            if not following:
                return None
            used[following[0]] = True
            more, a, b = pieces[following[0]]
            # A piece of several edges walked from its far end joins edge by edge backwards.
            chain.extend(more if a == current else more[::-1])
            current = b if a == current else a
        try:
            wire = Part.Wire(chain)
        except Part.OCCError:
            return None
        if not wire.isClosed():
            return None
        wires.append(wire)
    return wires


def _faces_of_wires(wires: list, plane) -> list[SectionFace] | None:
    """Faces on `plane` from closed wires: nesting depth decides outer loops and holes.

    A face built on the plane with one wire added (no orientation check, which would
    classify the infinite point) has a negative area when the wire turns clockwise about
    the normal; that sign orients every wire, and only wires whose boxes nest need a
    containment test.
    """
    _, Part = import_freecad()
    loops = []
    for wire in wires:
        alone = Part.Face(plane, [wire])
        area = alone.Area
        if abs(area) <= MIN_LOOP_AREA:
            return None
        # OCC's centre of mass divides the moments by the signed area: right either way.
        centroid = np.array(tuple(alone.CenterOfMass))
        loops.append((wire if area > 0 else wire.reversed(), abs(area), wire.BoundBox, centroid,
                      alone if area > 0 else None))
    loops.sort(key=lambda loop: -loop[1])
    parent: list[int | None] = []
    for i, (wire, _, box, _, _) in enumerate(loops):
        container = None
        for j in range(i - 1, -1, -1):   # the smallest enclosing loop comes last
            other_wire, _, other_box, _, _ = loops[j]
            if _box_inside(box, other_box) and _wire_inside(wire, other_wire, plane):
                container = j
                break
        parent.append(container)
    faces = []
    for i, (wire, area, _, centroid, alone) in enumerate(loops):
        if _depth(parent, i) % 2:
            continue
        holes = [k for k in range(len(loops)) if parent[k] == i]
        net = area - sum(loops[k][1] for k in holes)
        if net <= MIN_LOOP_AREA:
            return None
        moment = area * centroid - sum((loops[k][1] * loops[k][3] for k in holes), np.zeros(3))
        if holes or alone is None:
            face = Part.Face(plane, [wire] + [loops[k][0].reversed() for k in holes])
        else:
            face = alone     # one counter-clockwise loop: the face already built to orient it
        faces.append(SectionFace(face, float(net), moment / net))
    return faces


def _depth(parent: list[int | None], index: int) -> int:
    depth, above = 0, parent[index]
    while above is not None:
        depth, above = depth + 1, parent[above]
    return depth


def _box_inside(inner, outer) -> bool:
    """Inner box within outer one; boxes of edges are padded by their tolerances, hence slack."""
    slack = BOX_SLACK * (1.0 + outer.DiagonalLength)
    return (outer.XMin - slack <= inner.XMin and inner.XMax <= outer.XMax + slack
            and outer.YMin - slack <= inner.YMin and inner.YMax <= outer.YMax + slack
            and outer.ZMin - slack <= inner.ZMin and inner.ZMax <= outer.ZMax + slack)


def _wire_inside(wire, other, plane) -> bool:
    _, Part = import_freecad()
    edge = wire.Edges[0]
    probe = edge.valueAt(0.5 * (edge.FirstParameter + edge.LastParameter))
    return bool(Part.Face(plane, [other]).isInside(probe, 1e-9, True))
