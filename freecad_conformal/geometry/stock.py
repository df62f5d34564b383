"""The material a hybrid plan leaves, checked against the part (exact OCC solids).

Deposited nominal layers and the volumes the milling passes sweep are both prisms: a 2D
region in a frame, from a bottom height along the frame's normal for a height
(`Prism`). The result is (∪ deposits) − (∪ sweeps); compared with the part
it gives the volume left uncut (result − part), the volume gouged or never deposited
(part − result) and how far either reaches from the part's surface (stock standing
proud of it, a gouge or a shortfall sunk below it), measured at the vertices of the
difference solids and on a grid across their faces (a sampled one-sided Hausdorff
distance: a thin sliver between two grid points can be missed).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
import shapely

from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry.frames import LayerFrame

#: Difference solids smaller than this (mm³) are numerical slivers of coincident faces
#: (the flank of a finishing pass lies on the part's wall), not material.
SLIVER_VOLUME = 1e-4

#: Prisms this close (mm, mm²) in height and region are one stack.
STACKED = 1e-6

#: Deposit regions are simplified to this (mm) for the Booleans: they stand a stock
#: allowance (tenths of a millimetre) proud of the part, so the part is still covered.
DEPOSIT_SIMPLIFY = 0.01

#: Swept regions are simplified to this (mm): their inner side is the finished wall, so
#: this much can show as stock or gouge; sections come at 1 µm and cost the Booleans time.
SWEEP_SIMPLIFY = 0.002

#: Points sampled across each face of a difference solid (a grid this many to a side): a
#: solid's vertices lie on the part's edges, where the distance is 0; the depth of stock or
#: of a gouge shows inside the face that stands off the part's surface.
FACE_SAMPLES = 5

#: Faces of the other shape within this distance (mm) of a difference solid's box are the
#: ones its deviation is measured to: any stock or gouge beyond it is far larger than a
#: finishing tolerance and is still measured, to those faces, as at least this far.
NEAR_FACES = 2.0


@dataclass
class Prism:
    """A region (shapely, frame coordinates) from `bottom` along frame.n for `height`.
    `order` places it in time: a deposit made after `order` milling sessions, or the
    volume swept in session `order` (a session cuts what was deposited before it only)."""

    frame: LayerFrame
    region: object
    bottom: float
    height: float
    order: int = 0


@dataclass
class MaterialCheck:
    """What the plan leaves against the part (mm³ and mm)."""

    deposited: float
    removed: float
    uncut: float
    gouged: float
    max_uncut: float
    max_gouge: float

    @property
    def max_deviation(self) -> float:
        return max(self.max_uncut, self.max_gouge)


def prism_solid(prism: Prism):
    """An OCC solid for one prism (None when its region is empty)."""
    App, Part = import_freecad()
    polygons = [g for g in getattr(prism.region, "geoms", [prism.region])
                if g.geom_type == "Polygon" and not g.is_empty and g.area > 0]
    solids = []
    lift = App.Vector(*(prism.height * prism.frame.n))
    for polygon in polygons:
        wires = [_wire(Part, App, prism.frame, ring, prism.bottom)
                 for ring in [polygon.exterior, *polygon.interiors]]
        face = Part.makeFace(wires, "Part::FaceMakerBullseye")
        solids.append(face.extrude(lift))
    if not solids:
        return None
    return solids[0] if len(solids) == 1 else Part.makeCompound(solids)


def _wire(Part, App, frame: LayerFrame, ring, height: float):
    uv = np.asarray(ring.coords)
    points = frame.to_3d(uv, height)
    vectors = [App.Vector(*p) for p in points]
    if (points[0] != points[-1]).any():
        vectors.append(vectors[0])
    return Part.makePolygon(vectors)


def merged(prisms: Sequence[Prism]) -> list[Prism]:
    """Consecutive prisms of one region stacked on each other along one normal, as one
    (a prismatic stretch of layers is one solid for the Booleans, not one per layer)."""
    out: list[Prism] = []
    for prism in prisms:
        last = out[-1] if out else None
        if (last is not None and last.order == prism.order
                and np.allclose(last.frame.n, prism.frame.n)
                and np.allclose(last.frame.u, prism.frame.u)
                and abs(last.bottom + last.height - prism.bottom) <= STACKED
                and last.region.symmetric_difference(prism.region).area <= STACKED):
            out[-1] = Prism(last.frame, last.region, last.bottom, last.height + prism.height,
                            last.order)
        else:
            out.append(prism)
    return out


def grouped(prisms: Sequence[Prism]) -> list[Prism]:
    """Prisms of one frame, bottom and height as one (their regions united in 2D): the rows
    of a facing pass, the rings of one contour level."""
    groups: dict[tuple, list[Prism]] = {}
    for prism in prisms:
        key = tuple(np.round(np.concatenate((prism.frame.n, prism.frame.u,
                                             [prism.bottom, prism.height, prism.order])), 9))
        groups.setdefault(key, []).append(prism)
    out = []
    for members in groups.values():
        first = members[0]
        region = (first.region if len(members) == 1
                  else shapely.union_all([m.region for m in members]))
        out.append(Prism(first.frame, region, first.bottom, first.height, first.order))
    return out


def simplified(prisms: Sequence[Prism], tolerance: float) -> list[Prism]:
    return [Prism(p.frame, p.region.simplify(tolerance), p.bottom, p.height, p.order)
            for p in prisms]


def check_material(part, deposits: Sequence[Prism], sweeps: Sequence[Prism]) -> tuple[object, MaterialCheck]:
    """(the result as a compound, its check against `part`).

    Layers are disjoint slabs (each deposited on the one below, milled down before the
    next when it is a 3-D layer), so each is cut on its own: in 2D by the sweeps of its own
    frame that span its whole height (most of them: a wall pass reaches the flute length),
    by OCC with the others that reach it; then compared with the part. Many small
    operations instead of one fuse of every layer, which took minutes on a 74-layer part;
    only the gouge test takes the part against all of them at once."""
    App, Part = import_freecad()
    deposits = simplified(merged(deposits), DEPOSIT_SIMPLIFY)
    sweeps = simplified(grouped(sweeps), SWEEP_SIMPLIFY)
    solids = [prism_solid(p) for p in sweeps]
    boxes = [s.BoundBox if s is not None else None for s in solids]
    kept = []
    deposited = removed = uncut = max_uncut = 0.0
    for prism in deposits:
        whole = prism_solid(prism)
        if whole is None:
            continue
        deposited += float(whole.Volume)
        flat, rest = _cut_in_plane(prism, sweeps)
        solid = prism_solid(flat)
        if solid is None:
            removed += float(whole.Volume)
            continue
        box = solid.BoundBox
        hits = [solids[k] for k in rest if boxes[k] is not None and boxes[k].intersect(box)
                and sweeps[k].order >= prism.order]
        left = solid.cut(hits) if hits else solid
        removed += float(whole.Volume - left.Volume)
        proud = left.cut(part)
        uncut += _volume(proud)
        max_uncut = max(max_uncut, _farthest(proud, part))
        kept.append(left)
    if not kept:
        raise ValueError("no deposit to check")
    gouge = part.cut(kept)
    return Part.makeCompound(kept), MaterialCheck(
        deposited=deposited, removed=removed, uncut=uncut, gouged=_volume(gouge),
        max_uncut=max_uncut, max_gouge=_farthest(gouge, part))


def _cut_in_plane(prism: Prism, sweeps: Sequence[Prism]) -> tuple[Prism, list[int]]:
    """`prism` less, in 2D, the sweeps of its frame spanning its height; and the indices
    of the sweeps left for OCC (other frames, or a partial height)."""
    rest = []
    cutters = []
    top = prism.bottom + prism.height
    for k, sweep in enumerate(sweeps):
        if sweep.order < prism.order:
            continue                      # milled before this layer was deposited
        same = (np.allclose(sweep.frame.n, prism.frame.n) and np.allclose(sweep.frame.u, prism.frame.u))
        if not same:
            rest.append(k)
            continue
        if sweep.bottom + sweep.height <= prism.bottom + STACKED or sweep.bottom >= top - STACKED:
            continue                      # beside the slab: no overlap in height
        if sweep.bottom <= prism.bottom + STACKED and sweep.bottom + sweep.height >= top - STACKED:
            cutters.append(sweep.region)
        else:
            rest.append(k)
    if not cutters:
        return prism, rest
    region = prism.region.difference(shapely.union_all(cutters))
    return Prism(prism.frame, region, prism.bottom, prism.height, prism.order), rest


def _face_points(face) -> list:
    """Points on a grid across the face's parameter range that lie on the face."""
    u0, u1, v0, v1 = face.ParameterRange
    steps = (np.arange(FACE_SAMPLES) + 0.5) / FACE_SAMPLES
    return [face.valueAt(u, v) for u in u0 + (u1 - u0) * steps for v in v0 + (v1 - v0) * steps
            if face.isPartOfDomain(u, v)]


def _volume(shape) -> float:
    return float(sum(s.Volume for s in shape.Solids if s.Volume > SLIVER_VOLUME))


def _farthest(difference, other) -> float:
    """Largest distance from a point of `difference`'s non-sliver solids to `other`'s
    surface (measured to the faces of `other` near each solid: a point's nearest face
    touches the solid it lies on, and a whole-solid distance query is 50× slower)."""
    App, Part = import_freecad()
    worst = 0.0
    faces = other.Faces
    for solid in difference.Solids:
        if solid.Volume <= SLIVER_VOLUME:
            continue
        box = solid.BoundBox
        box.enlarge(NEAR_FACES)
        near = [f for f in faces if f.BoundBox.intersect(box)] or faces
        shell = Part.makeCompound(near)
        points = [v.Point for v in solid.Vertexes]
        for face in solid.Faces:
            points += _face_points(face)
        for point in points:
            worst = max(worst, float(shell.distToShape(Part.Vertex(point))[0]))
    return worst
