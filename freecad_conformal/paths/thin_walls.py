"""Thin walls: one bead along the middle of a feature narrower than a bead.

A perimeter is a bead's width inside the island's outline, so a wall narrower than a bead
(a 0.3 mm wall of a box under a 0.4 mm nozzle) gets no perimeter and no infill: it was left
out without a word. Such features are the island less what its external perimeter covers
(the island inset by half a bead, grown back). Each is laid as one bead along its medial
axis, as wide as the feature there (PrusaSlicer's "thin walls" / Arachne do the same): the
axis is the chordal axis of its constrained Delaunay triangulation (the Voronoi diagram of
its sampled outline with shapely < 2.1); spurs into the feature's corners are trimmed,
features too small or too narrow are left out (`MIN_WIDTH_SHARE`, `MIN_LENGTH_WIDTHS`), and
a bead is never narrower than `MIN_BEAD_SHARE` of the bead width.

Gap fill (`gap_beads`) lays the same beads along the gaps perimeter loops leave where a
loop had no room (`paths.fill2d.perimeter_walls`), each as wide as fills its gap; pieces
whose ends meet are joined into one bead (`joined_beads`).
"""
from __future__ import annotations

from collections import Counter

import numpy as np
import shapely
from shapely.geometry import LineString, MultiLineString, MultiPoint, Polygon

from freecad_conformal.geometry.loops import grid_key, signed_area
from freecad_conformal.shapely_speed import mitred_buffer
from freecad_conformal.tolerances import COINCIDENT_POINTS

#: Narrower than this share of the bead, a feature is left out (PrusaSlicer's Arachne: its
#: smallest feature, `min_feature_size`, is a quarter of the nozzle).
MIN_WIDTH_SHARE = 0.25

#: The narrowest bead laid, as a share of the bead width: a narrower one is not a stable
#: bead (it would be narrower than most layers are high); a narrower feature gets this one
#: (Arachne's `min_bead_width`, 85 % of the nozzle).
MIN_BEAD_SHARE = 0.85

#: A thin-wall bead shorter than this many bead widths is a corner's sliver (the tip of an
#: acute corner the mitre limit bevels off the perimeter), not a wall.
MIN_LENGTH_WIDTHS = 2.0

#: Outline samples per bead width where the axis comes from a Voronoi diagram (shapely
#: < 2.1): fewer leave the middle off by a sample spacing squared over the wall's width.
SAMPLES_PER_WIDTH = 4

#: Branches of the axis shorter than this many bead widths with a free end are spurs into
#: the feature's corners.
SPUR_WIDTHS = 1.0

#: GEOS improves its ear-clipped triangulation into the constrained Delaunay one in at most
#: 200 rounds of edge flips, too few for the fans ear clipping leaves along long sampled
#: straight sides: a 0.3 mm wall round a 50 x 40 mm box (1,794 outline samples) got beads
#: zigzagging across the wall, cut in four and a fifth too long (round 40 x 40 mm, 1,594
#: samples, it was right; a straight 80 mm fin, 805, too). A feature sampled more often
#: than this is triangulated in square tiles `TILE_WIDTHS` bead widths wide.
TILE_SAMPLES = 1000
TILE_WIDTHS = 25.0

#: A gap-fill bead fills a gap at most this many bead spacings wide (PrusaSlicer's gap fill
#: `max`): a dropped loop leaves a gap under 1.6 spacings (`paths.fill2d.LOOP_ROOM`), so
#: only a junction's median could ask for more.
GAP_MAX_SPACINGS = 2.0


def thin_features(island: Polygon, width: float, eroded, mitre_limit: float) -> list[Polygon]:
    """The parts of `island` narrower than a bead of `width`: the island less what its
    external perimeter covers (`eroded`: the island inset by half a width with mitred
    corners, where that bead's middle runs, grown back alike, so a corner the perimeter
    turns is no feature)."""
    smallest = MIN_WIDTH_SHARE * MIN_LENGTH_WIDTHS * width * width
    if eroded.is_empty:
        left = island
    else:
        with np.errstate(divide="ignore", invalid="ignore"):    # as the inset: see fill2d
            grown = mitred_buffer(eroded, 0.5 * width, mitre_limit)
        if island.area - grown.area < smallest:
            # What the perimeter covers lies inside the island: all it leaves is less
            # than one feature (most islands; the difference was 90 % of this work).
            return []
        left = island.difference(grown)
    parts = getattr(left, "geoms", [left])
    return [p for p in parts if p.geom_type == "Polygon" and not p.is_empty
            and p.area >= smallest]


def medial_lines(feature: Polygon, width: float) -> list[LineString]:
    """The feature's medial axis as merged lines, spurs shorter than `SPUR_WIDTHS` bead
    widths trimmed."""
    pieces = None
    if hasattr(shapely, "constrained_delaunay_triangles"):
        try:
            pieces = _chordal_axis(feature, width)
        except shapely.errors.GEOSException:
            # GEOS's ear clipping gives up on some slivers ("Unable to find a convex
            # corner": a fan blade's 9 mm long, 2 µm wide trailing edge): the Voronoi axis
            # does not triangulate.
            pieces = None
    if pieces is None:          # shapely < 2.1, or the triangulation failed
        pieces = _voronoi_axis(feature, width)
    if not pieces:
        return []
    lines = _merged(pieces)
    for _ in range(4):          # spurs off spurs: a few rounds settle every real feature
        kept = _without_spurs(lines, SPUR_WIDTHS * width)
        if len(kept) == len(lines):
            break
        lines = _merged(kept)
    return lines


def _chordal_axis(feature: Polygon, width: float) -> list[LineString]:
    """The chordal axis of the feature's constrained Delaunay triangulation (its outline
    sampled every half bead, so a long straight wall has triangles across it): in each
    triangle with two inner edges, the segment between their middles; with three, each
    middle to the centroid. In a wall between parallel sides every middle lies on the
    wall's middle line (a 0.3 mm square wall: 78.8 of 78.8 mm, 5 ms). A long feature is
    triangulated in tiles (`TILE_SAMPLES`)."""
    outline = shapely.segmentize(feature, 0.5 * width)
    if shapely.get_num_coordinates(outline) > TILE_SAMPLES:
        outline = _tiles(outline, TILE_WIDTHS * width)
    triangles = shapely.get_parts(shapely.constrained_delaunay_triangles(outline))
    if not len(triangles):
        return []
    corners = shapely.get_coordinates(triangles).reshape(len(triangles), 4, 2)[:, :3]
    edges = corners[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2, 2)        # (3n, 2 ends, xy)
    ends = np.round(edges, 9)
    swap = (ends[:, 0, 0] > ends[:, 1, 0]) | ((ends[:, 0, 0] == ends[:, 1, 0])
                                              & (ends[:, 0, 1] > ends[:, 1, 1]))
    ends[swap] = ends[swap][:, ::-1]
    _, inverse, counts = np.unique(ends.reshape(-1, 4), axis=0, return_inverse=True,
                                   return_counts=True)
    inner = (counts[inverse.ravel()] == 2).reshape(-1, 3)          # shared by two triangles
    middles = edges.mean(axis=1).reshape(-1, 3, 2)
    sleeves = inner.sum(axis=1) == 2
    segments = [middles[sleeves][inner[sleeves]].reshape(-1, 2, 2)]
    junctions = inner.all(axis=1)
    if junctions.any():
        centres = np.repeat(corners[junctions].mean(axis=1), 3, axis=0)
        segments.append(np.stack([middles[junctions].reshape(-1, 2), centres], axis=1))
    segments_array = np.concatenate(segments)
    return list(shapely.linestrings(segments_array)) if len(segments_array) else []


def _tiles(outline: Polygon, size: float) -> np.ndarray:
    """The (sampled) feature's pieces in tiles about `size` (mm) square. Neighbouring pieces
    share each cut across the feature as one edge (the same two points, from the same
    outline edges: cut after sampling, so no sample lies inside the feature), an inner edge
    of their triangles whose middle the axis runs through."""
    xs = _cuts(outline, 0, size)
    ys = _cuts(outline, 1, size)
    x0, y0 = np.meshgrid(xs[:-1], ys[:-1])
    x1, y1 = np.meshgrid(xs[1:], ys[1:])
    tiles = shapely.box(x0.ravel(), y0.ravel(), x1.ravel(), y1.ravel())
    pieces = shapely.get_parts(shapely.intersection(outline, tiles))
    return pieces[(shapely.get_type_id(pieces) == 3) & ~shapely.is_empty(pieces)]


#: A cut passes at least this far (mm) from every outline sample: one a rounding error off
#: the cut would leave an edge of next to no length along it on one side only, and the two
#: sides' edges there would not match.
CUT_CLEARANCE = 1e-6

#: Places tried for each cut, spread over a quarter tile either side of its own: a cut
#: along a strip (a grid line through a rib's gap) runs inside it as one long edge no
#: triangle crosses, and the axis broke there (the hollow box's gap fill in 10 mm tiles:
#: its beads in 15 pieces, 16 % too long). The cut is made where its longest stretch inside
#: the feature is shortest.
CUT_TRIES = 11


def _cuts(outline: Polygon, axis: int, size: float) -> np.ndarray:
    """Tile edges across `axis` (0: x, 1: y) from beyond the outline's bounds on one side
    to beyond them on the other, about `size` apart: each where it crosses the feature in
    the shortest stretches (`CUT_TRIES`) and clear of every sample (`CUT_CLEARANCE`)."""
    bounds = np.asarray(outline.bounds)
    low, high = bounds[axis], bounds[axis + 2]
    places = np.arange(low + size, high, size)
    if not len(places):
        return np.array([low - size, high + size])
    steps = np.arange(CUT_TRIES) - CUT_TRIES // 2
    tries = steps[np.argsort(np.abs(steps), kind="stable")] * (0.5 * size / (CUT_TRIES - 1))
    candidates = places[:, None] + tries[None, :]
    longest = _longest_inside(outline, axis, candidates.ravel()).reshape(candidates.shape)
    chosen = candidates[np.arange(len(places)), np.argmin(longest, axis=1)]
    values = shapely.get_coordinates(outline)[:, axis]
    cuts = []
    for cut in chosen:
        while np.any(np.abs(values - cut) < CUT_CLEARANCE):
            cut += 2.0 * CUT_CLEARANCE
        cuts.append(cut)
    return np.array([low - size, *cuts, high + size])


def _longest_inside(outline: Polygon, axis: int, positions: np.ndarray) -> np.ndarray:
    """Per line across `axis` at each of `positions`, the longest stretch of it inside the
    outline: its crossings of the rings' edges, paired along it (even-odd)."""
    rings = [np.asarray(ring.coords) for poly in getattr(outline, "geoms", [outline])
             for ring in (poly.exterior, *poly.interiors)]
    starts = np.concatenate([ring[:-1] for ring in rings])
    ends = np.concatenate([ring[1:] for ring in rings])
    a, b = starts[:, axis], ends[:, axis]
    low, high = np.minimum(a, b)[:, None], np.maximum(a, b)[:, None]
    edge, line = np.nonzero((low <= positions[None, :]) & (positions[None, :] < high))
    share = (positions[line] - a[edge]) / (b[edge] - a[edge])
    other = starts[edge, 1 - axis] + share * (ends[edge, 1 - axis] - starts[edge, 1 - axis])
    order = np.lexsort((other, line))
    line, other = line[order], other[order]
    longest = np.zeros(len(positions))
    if len(line) >= 2:
        # each line crosses closed rings an even number of times: pairs in order
        np.maximum.at(longest, line[0::2], other[1::2] - other[0::2])
    return longest


def _voronoi_axis(feature: Polygon, width: float) -> list[LineString]:
    """The Voronoi edges of the feature's outline, sampled `SAMPLES_PER_WIDTH` times a bead
    width, that lie inside it (slower: ~0.1 s for a 0.3 mm square wall)."""
    step = width / SAMPLES_PER_WIDTH
    outline = shapely.segmentize(feature, step)
    if outline.geom_type == "Polygon":
        points = np.vstack([np.asarray(ring.coords)[:-1]
                            for ring in (outline.exterior, *outline.interiors)])
    else:       # a sliver's outline may come back in parts: every ring's points, once
        points = np.unique(shapely.get_coordinates(outline), axis=0)
    edges = shapely.voronoi_polygons(MultiPoint(points), only_edges=True)
    pieces = np.asarray(shapely.get_parts(edges))
    if not len(pieces):
        return []
    return list(pieces[shapely.contains_properly(feature, pieces)])


def _merged(lines: list[LineString]) -> list[LineString]:
    merged = shapely.line_merge(MultiLineString(lines))
    return [line for line in getattr(merged, "geoms", [merged]) if not line.is_empty]


def _without_spurs(lines: list[LineString], shortest: float) -> list[LineString]:
    """The lines less those shorter than `shortest` with an end no other line meets."""
    ends = [tuple(np.round(line.coords[k], 9)) for line in lines for k in (0, -1)]
    counts = Counter(ends)
    kept = []
    for k, line in enumerate(lines):
        free = counts[ends[2 * k]] == 1 or counts[ends[2 * k + 1]] == 1
        if free and not line.is_ring and line.length < shortest and len(lines) > 1:
            continue
        kept.append(line)
    return kept


def medial_beads(features: list[Polygon], width: float) -> list[tuple[np.ndarray, float, bool]]:
    """(points (N, 2), median width, closed) of each line of the features' medial axes
    (`medial_lines`) at least `MIN_LENGTH_WIDTHS` bead widths long: the width is twice the
    distance to the feature's outline, its median along the line (ends and joins are
    narrower). A feature the same as one met before but moved (a heat sink's fins) takes
    that one's beads, moved (`_AXES`)."""
    beads = []
    for feature in features:
        corner = np.asarray(feature.bounds[:2])
        key = (grid_key(feature, COINCIDENT_POINTS, corner), width)
        found = _AXES.get(key)
        if found is None:
            made = _feature_beads(feature, width)
            _AXES[key] = [(points - corner, median, closed) for points, median, closed in made]
            if len(_AXES) > MAX_AXES:
                _AXES.pop(next(iter(_AXES)))
            beads += made           # the first its own, bit for bit
        else:
            beads += [(points + corner, median, closed) for points, median, closed in found]
    return beads


#: Beads of features met before, by outline (moved to its box's corner, to
#: `COINCIDENT_POINTS`) and bead width, oldest first: the 12 fins of a heat sink gave 156
#: gap axes a plan (0.7 s of its 2.2 s), 13 of them different. At most MAX_AXES are kept.
_AXES: dict[tuple, list] = {}
MAX_AXES = 4096


def _feature_beads(feature: Polygon, width: float) -> list[tuple[np.ndarray, float, bool]]:
    beads = []
    boundary = feature.boundary
    for line in medial_lines(feature, width):
        if line.length < MIN_LENGTH_WIDTHS * width:
            continue
        along = shapely.get_coordinates(shapely.segmentize(line, 0.5 * width))
        wide = 2.0 * shapely.distance(boundary, shapely.points(along))
        points = np.asarray(line.simplify(0.25 * width / SAMPLES_PER_WIDTH).coords)
        if line.is_ring and signed_area(points) > 0.0:
            points = points[::-1].copy()        # clockwise, as the outline's loops run
        beads.append((points, float(np.median(wide)), bool(line.is_ring)))
    return beads


def thin_wall_beads(island: Polygon, width: float, eroded,
                    mitre_limit: float) -> list[tuple[np.ndarray, float, bool]]:
    """(points (N, 2), bead width, closed) of each thin-wall bead of `island` (`eroded`:
    the island inset by half a width with mitred corners up to `mitre_limit`, see
    `thin_features`): along the medial axis of each feature narrower than `width` whose
    median width along it is `MIN_WIDTH_SHARE` of `width` at least; the bead as wide as
    that median, but `MIN_BEAD_SHARE` of `width` at least and `width` at most."""
    return [(points, min(max(median, MIN_BEAD_SHARE * width), width), closed)
            for points, median, closed in medial_beads(
                thin_features(island, width, eroded, mitre_limit), width)
            if median >= MIN_WIDTH_SHARE * width]


def gap_beads(gaps: list[Polygon], width: float,
              spacing: float) -> list[tuple[np.ndarray, float, bool]]:
    """(points (N, 2), bead width, closed) of the gap-fill beads of `gaps` (gaps between
    the centres of neighbouring beads, measured between their half-spacing lines): along
    each gap's medial axis (`medial_beads`), wide enough that the bead's spacing is the
    gap's median width (a bead of width w fills a strip w − (width − spacing) wide: the
    bead model's spacing rule), so the wall is filled neither over nor under. Gaps under
    `MIN_WIDTH_SHARE` of a bead are left. A gap bead is not held to `MIN_BEAD_SHARE`: it
    is laid between two beads that hold it, not standing alone as a thin wall does."""
    squeeze = width - spacing
    return [(points, min(median, GAP_MAX_SPACINGS * spacing) + squeeze, closed)
            for points, median, closed in medial_beads(gaps, width)
            if median >= MIN_WIDTH_SHARE * width]


#: Gap-bead ends closer than this share of a bead width are one bead's end: a gap's axis
#: breaks into pieces at its junctions (a rib meeting a wall: three pieces ending at one
#: point), and each piece was one start and one stop. Ends this close lie under one bead's
#: round end (half a width); the pieces of the sample parts meet exactly.
JOIN_REACH_SHARE = 0.25

#: Gap beads whose widths differ by less than this share of a bead width are joined as one
#: bead of their length-weighted mean width (the same material wherever a bead is wider
#: than the layer is high: its cross-section is linear in its width there). The pieces of
#: one wall's gap differ by their sampling only (the hollow box's: not at all); a 1 mm rib
#: in a box of 1.2 mm walls is half a bead narrower and stays apart.
JOIN_WIDTH_SHARE = 0.05


def joined_beads(beads: list[tuple[np.ndarray, float, bool]],
                 width: float) -> list[tuple[np.ndarray, float, bool]]:
    """The open beads of `beads` ((points, bead width, closed), as `gap_beads` gives them)
    joined where their ends meet (`JOIN_REACH_SHARE`) and their widths agree
    (`JOIN_WIDTH_SHARE`) into one polyline each, fewer starts and stops; where several
    ends meet, the straightest pair first (a wall's two pieces through a rib's junction,
    not a piece into the rib). A join stays open (closed beads keep their feed rule:
    `paths.assemble.Feeds.for_path`); closed beads are kept as they are."""
    chains = [(np.asarray(points, dtype=float), bead) for points, bead, closed in beads
              if not closed and len(points) >= 2]
    kept = [b for b in beads if b[2] or len(b[0]) < 2]
    reach, alike = JOIN_REACH_SHARE * width, JOIN_WIDTH_SHARE * width
    while len(chains) > 1:
        best = _straightest_join(chains, reach, alike)
        if best is None:
            break
        i, j, i_tail, j_head = best
        (a, wa), (b, wb) = chains[i], chains[j]
        a = a if i_tail else a[::-1]
        b = b if j_head else b[::-1]
        la, lb = _polyline_length(a), _polyline_length(b)
        if np.linalg.norm(a[-1] - b[0]) <= COINCIDENT_POINTS:
            b = b[1:]               # the shared end once
        joined = (np.vstack((a, b)), (wa * la + wb * lb) / (la + lb) if la + lb > 0 else wa)
        chains = [c for k, c in enumerate(chains) if k not in (i, j)] + [joined]
    return kept + [(points, bead, False) for points, bead in chains]


def _polyline_length(points: np.ndarray) -> float:
    return float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum())


def _straightest_join(chains: list[tuple[np.ndarray, float]], reach: float,
                      alike: float) -> tuple[int, int, bool, bool] | None:
    """(i, j, join at i's tail, join at j's head) of the two chains whose ends meet within
    `reach`, widths within `alike`, that turn least there; None when no two do."""
    ends = np.array([[c[0][0], c[0][-1]] for c in chains]).reshape(-1, 2)    # 2k: head, 2k+1: tail
    owner = np.repeat(np.arange(len(chains)), 2)
    widths = np.array([c[1] for c in chains])[owner]
    apart = np.linalg.norm(ends[:, None, :] - ends[None, :, :], axis=2)
    meets = ((apart <= reach) & (owner[:, None] < owner[None, :])
             & (np.abs(widths[:, None] - widths[None, :]) < alike))
    best, straightest = None, -np.inf
    for p, q in zip(*np.nonzero(meets)):
        i, j = int(owner[p]), int(owner[q])
        i_tail, j_head = bool(p % 2), not q % 2
        # Direction into the meeting end along i, and out of it along j.
        into = _end_direction(chains[i][0], i_tail)
        out = -_end_direction(chains[j][0], not j_head)
        straight = float(into @ out)
        if straight > straightest:
            best, straightest = (i, j, i_tail, j_head), straight
    return best


def _end_direction(points: np.ndarray, tail: bool) -> np.ndarray:
    """Unit direction in which the polyline arrives at its tail (`tail`), or at its head
    when run backwards; zero when it has no length."""
    seq = points if tail else points[::-1]
    steps = np.diff(seq, axis=0)
    lengths = np.linalg.norm(steps, axis=1)
    moving = np.nonzero(lengths > 0)[0]
    if not len(moving):
        return np.zeros(2)
    k = moving[-1]
    return steps[k] / lengths[k]
