"""2D deposition paths of one layer (shapely): perimeters, zigzag infill, seams, travel order.

- Perimeters: the external one's centre half a bead width inside the region, each further
  one a bead spacing (`paths.bead`: the distance that fills the slab, for the layer height)
  further in (mitred corners), outer boundaries and holes alike; printed innermost first,
  the external one last (its surface is the part's, so it goes on last, as slicers do).
- Infill: what is left inside the last perimeter, reaching `infill_overlap` of a spacing
  into it so the two bond (PrusaSlicer's infill_overlap; lines end `LINE_END_INSET` of a
  spacing short of that edge, as PrusaSlicer's do); sparse where `density` < 1 (line
  spacing = bead spacing / density), solid (one bead spacing) in `solid` areas (top/bottom
  skins) and in sparse pieces smaller than `solid_below_area` (PrusaSlicer's
  solid_infill_below_area: a sparse grid in a small region carries nothing).
  Lines are zigzags linked by short connectors that stay inside the infill area, along the
  direction that needs the fewest turns (or a given angle), turned 90° on odd layers.
- Seams: "aligned" (the rearmost vertex: +v), "nearest" (closest to the nozzle) or
  "sharpest" (the sharpest corner hides it).
- Order: islands, loops and infill chains are taken greedily nearest-first from the
  nozzle's position, infill chains in whichever direction starts closer (`ordered_fill`,
  apart from the fill itself, `layer_fill`, which does not depend on the position). An
  island's beads along middles (thin walls, gap fill) follow its loops, before its infill
  (PrusaSlicer's order: perimeters with thin walls, gap fill, infill), nearest-first from
  where the loops end.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import shapely
from shapely import affinity
from shapely.geometry import LineString, MultiPolygon, Polygon

from freecad_conformal.errors import PlanError
from freecad_conformal.paths.bead import BEAD_MODELS, bead_spacing
from freecad_conformal.paths.scan import (CANDIDATE_ANGLES, boundary_edges, bridge_angle,
                                          polygons_of, scan_pieces, span_angle)
from freecad_conformal.paths.thin_walls import (MIN_LENGTH_WIDTHS, MIN_WIDTH_SHARE,
                                                 gap_beads, joined_beads, thin_wall_beads)
from freecad_conformal.shapely_speed import mitred_buffer
from freecad_conformal.tolerances import COINCIDENT_POINTS

ROLES = ("external_perimeter", "perimeter", "infill", "solid_infill")
#: Infill roles laid at one spacing (solid areas and bridges over sparse infill).
SOLID_ROLES = ("solid_infill", "bridge_infill")
SEAMS = ("aligned", "nearest", "sharpest")

#: Mitre limit of the perimeter offsets: keeps 90° corners sharp (ratio √2) while a very
#: acute corner is bevelled instead of spiking out.
MITRE_LIMIT = 2.0


def inset(geometry, distance: float):
    """`geometry` shrunk by `distance` (mm) with mitred corners (`MITRE_LIMIT`)."""
    # A corner whose two edges end a last bit apart (a section's near-spike) makes GEOS
    # divide by a zero length and numpy flag it; GEOS bevels that corner and the result is
    # valid (checked on the fan's two such islands), so the flag says nothing to a user.
    with np.errstate(divide="ignore", invalid="ignore"):
        return mitred_buffer(geometry, -distance, MITRE_LIMIT)


#: Zigzag rows are linked along the area's boundary when the way round is at most this many
#: line spacings (a boundary slanting 15° to the lines): longer, a travel is shorter.
LINK_ROWS = 4.0

#: A scan line's end lies on the area's boundary to within this (mm): it is an intersection
#: with that boundary.
ON_BOUNDARY = 1e-6

#: Infill lines end this fraction of a bead spacing inside the infill area, so the bead's
#: end, like its sides, reaches the area's edge and overlaps the innermost perimeter by
#: `infill_overlap` only: PrusaSlicer 2.5 clips its lines to the fill area offset by half a
#: spacing (FillRectilinear: `overlap - 0.5 * spacing`); its line ends lie 0.31 mm inside
#: the inner perimeter's centre line, as these do (0.75 of a 0.407 mm spacing). At 0.2 the
#: lines ran 0.12 mm further at each end: on the screw's narrow shank, 9 % more solid
#: infill than PrusaSlicer's.
LINE_END_INSET = 0.5

#: Loops shorter than this many bead widths are dust left by offsetting thin features.
MIN_LOOP_WIDTHS = 2.0

#: An inner loop is laid only where the inset it follows is at least this many bead
#: spacings wide, so two stretches of one loop (or two loops) are never closer: PrusaSlicer's
#: min_spacing, a spacing less its INSET_OVERLAP_TOLERANCE of 40 %. Every loop used to be
#: laid wherever its inset was not empty: a 1.2 mm wall (0.4 mm beads, 0.2 mm layers) got
#: two inner loops 0.086 mm apart, their beads overlapping by 75 %, and 13-19 % more
#: material than the wall holds; where a loop has no room, gap fill fills the gap instead.
LOOP_ROOM = 0.6

#: An opened inset whose area differs from the inset's by less than this (mm²) lost
#: nothing: the inset's own vertices are kept (offsetting back and forth only rounds them),
#: so walls with room for every loop keep the paths they had.
OPENING_NOISE = 1e-6

#: Connectors between zigzag lines may lie this far (as a fraction of the bead width) outside
#: the infill area: they run along its boundary, where rounding puts them either side.
CONNECTOR_SLACK = 0.05


@dataclass
class Path2D:
    """A polyline in layer coordinates; `closed` loops repeat their first point at the end."""

    points: np.ndarray
    role: str
    closed: bool = False
    #: bead width where it is not the settings' (solid lines spread to fill their area)
    width: float | None = None

    @property
    def length(self) -> float:
        return float(np.linalg.norm(np.diff(self.points, axis=0), axis=1).sum())

    def reversed(self) -> "Path2D":
        return Path2D(self.points[::-1].copy(), self.role, self.closed, self.width)


@dataclass
class FillSettings:
    """Bead width (mm), perimeter count, sparse density 0..1, infill angle (rad, None: fewest
    turns), 90° alternation on odd layers, seam placement, bead model (`paths.bead`),
    infill overlap into the innermost perimeter (fraction of a bead spacing) and the area
    (mm²) under which a sparse infill piece is printed solid. The defaults are
    PrusaSlicer's (rounded beads, 25 %, 70 mm²)."""

    bead_width: float = 0.4
    perimeters: int = 2
    density: float = 0.2
    angle: float | None = None
    alternate: bool = True
    seam: str = "aligned"
    bead_model: str = "rounded"
    infill_overlap: float = 0.25
    solid_below_area: float = 70.0

    def validate(self) -> None:
        if not (isinstance(self.bead_width, (int, float)) and math.isfinite(self.bead_width)
                and self.bead_width > 0):
            raise PlanError(f"bead width must be a positive number of mm, got {self.bead_width!r}")
        if not (isinstance(self.perimeters, int) and self.perimeters >= 0):
            raise PlanError(f"perimeter count must be a whole number >= 0, got {self.perimeters!r}")
        if not (math.isfinite(self.density) and 0.0 <= self.density <= 1.0):
            raise PlanError(f"infill density must be a fraction 0..1, got {self.density!r}")
        if self.angle is not None and not math.isfinite(self.angle):
            raise PlanError(f"infill angle must be finite, got {self.angle!r}")
        if self.seam not in SEAMS:
            raise PlanError(f"seam {self.seam!r} is not one of {', '.join(SEAMS)}")
        if self.bead_model not in BEAD_MODELS:
            raise PlanError(f"bead model {self.bead_model!r} is not one of {', '.join(BEAD_MODELS)}")
        if not (math.isfinite(self.infill_overlap) and 0.0 <= self.infill_overlap < 1.0):
            raise PlanError(f"infill overlap must be a fraction 0..1 of a bead spacing, "
                            f"got {self.infill_overlap!r}")
        if not (math.isfinite(self.solid_below_area) and self.solid_below_area >= 0.0):
            raise PlanError(f"solid infill area threshold must be >= 0 mm2, got {self.solid_below_area!r}")


def valid_region(geometry):
    """The geometry, repaired when invalid (shapely.make_valid keeps every covered area)."""
    if geometry is None or geometry.is_empty or geometry.is_valid:
        return geometry
    return shapely.make_valid(geometry)


@dataclass
class Walls:
    """An island's perimeters: rings per depth (0 the external one), each an (N, 2) closed
    polyline, and the gaps they leave where a loop had no room, to be filled along their
    middle (`gap_fill`): between loops (`gaps`) and inside the innermost ones (`interior`,
    which the infill leaves to gap fill where a bead fills it)."""

    depths: list[list[np.ndarray]]
    gaps: list[Polygon]
    interior: list[Polygon]
    #: the loops' bead width and spacing (mm): the settings' unless widened (`island_walls`)
    width: float = 0.0
    spacing: float = 0.0


def _opened(geometry, distance: float):
    """`geometry` less its parts narrower than twice `distance` (mitred, as `inset`)."""
    with np.errstate(divide="ignore", invalid="ignore"):    # as in `inset`
        return mitred_buffer(inset(geometry, distance), distance, MITRE_LIMIT)


def perimeter_walls(island: Polygon, width: float, count: int, spacing: float | None = None,
                    external=None) -> Walls:
    """The island's perimeter loops and the gaps between them (`Walls`). The external loop
    runs half a width in (`external`: the island inset so, when the caller has it); each
    further one `spacing` (default the width) further in, but only where its inset is at
    least `LOOP_ROOM` spacings wide (PrusaSlicer's classic perimeters: the inset opened).
    Where a loop has no room, the strip between the half-spacing lines of the loops around
    it is a gap; so is the strip inside the innermost loops where one more would have none
    (PrusaSlicer looks one loop further for these gaps)."""
    spacing = width if spacing is None else spacing
    external = inset(island, 0.5 * width) if external is None else external
    depths: list[list[np.ndarray]] = []
    gaps: list[Polygon] = []
    left: list[Polygon] = []        # the last level's gaps: inside the innermost loops at the end
    previous = external
    for k in range(count + 1):
        if k == 0:
            offset = external
        else:
            plain = inset(island, 0.5 * width + k * spacing)
            offset = _opened(plain, 0.5 * LOOP_ROOM * spacing)
            if abs(plain.area - offset.area) <= OPENING_NOISE:
                offset = plain
            gaps += left
            left = _gap(previous, offset, width, spacing)
        if k == count:
            break
        rings = [np.asarray(ring.coords) for poly in polygons_of(offset)
                 for ring in [poly.exterior, *poly.interiors] if ring.length >= MIN_LOOP_WIDTHS * width]
        if not rings:
            break
        depths.append(rings)
        previous = offset
    return Walls(depths, gaps, left, width, spacing)


#: The most an island's loops are widened (a share of the bead width) to fill the band
#: they leave inside the innermost ones (`island_walls`). A 2 mm tube wall holds two
#: 0.45 mm loops a side and a 0.33 mm band, one more loop of gap fill on every layer (19 %
#: of a pipe tee's deposits); widened by 0.08 mm, the four loops fill it. PrusaSlicer's
#: Arachne varies every bead's width instead.
MAX_WIDENING = 0.25

#: Area (mm²) inside an island's innermost loops beyond the band they leave that still
#: counts as none: what offsetting back and forth leaves (OPENING_NOISE's scale).
BAND_REST = 1e-3


def island_walls(island: Polygon, width: float, count: int, spacing: float,
                 external=None) -> Walls:
    """`perimeter_walls`, or where the island is all wall and its loops leave one band
    inside the innermost ones (no loop between missing, nothing for infill), the loops
    each widened by a share of the band (at most `MAX_WIDENING`) when that fills it: the
    same loops, no gap fill. The loops laid count, not `count`: a wall with room for two
    loops a side is one whether three or more were asked for."""
    walls = perimeter_walls(island, width, count, spacing, external)
    laid = len(walls.depths)
    if not laid or walls.gaps or not walls.interior:
        return walls
    rest = inset(island, 0.5 * width + (laid - 0.5) * spacing)
    band = sum(piece.area for piece in walls.interior)
    if rest.area - band > BAND_REST:
        return walls            # the loops leave more than the band: infill
    # A thin band's area over half its outline is its mean width; its loops and those of
    # the other side (2 x laid in all) share it.
    grow = band / sum(piece.length for piece in walls.interior) / laid
    if grow > MAX_WIDENING * width:
        return walls
    wide = perimeter_walls(island, width + grow, count, spacing + grow)
    if (wide.gaps or wide.interior
            or [len(rings) for rings in wide.depths] != [len(rings) for rings in walls.depths]):
        return walls            # the band is not even: a loop lost room, or a gap is left
    return wide


def _gap(outer, inner, width: float, spacing: float) -> list[Polygon]:
    """What lies between loops along `outer` (a region of loop centres) and along `inner`
    (the next one, a spacing in) uncovered by either's half spacing: the strips where a
    loop had no room. Slivers of offsets that do not quite meet, parts under
    `MIN_WIDTH_SHARE` of a bead wide (which gap fill leaves) and pieces too small to hold
    a bead `MIN_LENGTH_WIDTHS` long are left out."""
    if outer.is_empty:
        return []
    smallest = MIN_WIDTH_SHARE * MIN_LENGTH_WIDTHS * width * width
    reach = inset(outer, 0.5 * spacing)
    if not inner.is_empty:
        with np.errstate(divide="ignore", invalid="ignore"):    # as in `inset`
            covered = mitred_buffer(inner, 0.5 * spacing, MITRE_LIMIT)
        if reach.area - covered.area < smallest:
            # Less than the smallest gap a bead fills is left (most loops: the work of
            # the difference and the opening saved).
            return []
        reach = reach.difference(covered)
    return [piece for piece in polygons_of(_opened(reach, 0.5 * MIN_WIDTH_SHARE * width))
            if piece.area >= smallest]


def perimeter_rings(island: Polygon, width: float, count: int,
                    spacing: float | None = None, external=None) -> list[list[np.ndarray]]:
    """Rings per depth of `perimeter_walls` (0 = external, half a width in; each next one
    `spacing` further, default the width, where it has room): each an (N, 2) closed
    polyline."""
    return perimeter_walls(island, width, count, spacing, external).depths


def _scan_segments(area, spacing: float, angle: float,
                   phase: float = 0.5) -> list[list[tuple[float, float, float]]]:
    """Per scan line, in order, the (x0, x1, y) pieces inside `area`, sorted along the line."""
    pieces, first = scan_pieces(area, spacing, angle, phase)
    if len(pieces) == 0:
        return []
    pieces = pieces[np.lexsort((pieces[:, 2], pieces[:, 1], pieces[:, 0]))]
    breaks = np.flatnonzero(np.diff(pieces[:, 0])) + 1
    result = []
    for group in np.split(pieces, breaks):
        y = (first + int(group[0, 0])) * spacing
        result.append([(float(x0), float(x1), y) for _, x0, x1 in group])
    return result


def fewest_turns_angle(area, spacing: float) -> float:
    """The candidate direction whose zigzag has the fewest line pieces (so fewest turns).

    A scan line's pieces inside the area are half its crossings of the area's boundary, so
    the count for each direction comes from the boundary's edges alone: the grid lines
    (same global grid as `scan_pieces`) each edge spans, over all edges and candidate
    directions at once in numpy, instead of one GEOS intersection per direction. A vertex
    exactly on a grid line can make this count differ from GEOS's by a piece, so where
    directions tie the choice may differ from counting GEOS pieces (CrankArm: 2 of 1,558
    layers, each with the same number of pieces either way)."""
    edges = boundary_edges(area)
    if edges is None:
        return CANDIDATE_ANGLES[0]
    starts, ends = edges
    angles = np.asarray(CANDIDATE_ANGLES)
    # y in the rotated frame (rotated by -angle): -x sin(a) + y cos(a)
    normal = np.column_stack((-np.sin(angles), np.cos(angles)))
    y0, y1 = starts @ normal.T, ends @ normal.T                     # (edges, angles)
    low, high = np.minimum(y0, y1), np.maximum(y0, y1)
    # grid lines y = (j + 0.5) * spacing with low <= y < high (half-open: a vertex on a
    # line is counted once, by the edge that leaves it upwards)
    crossings = (np.ceil(high / spacing - 0.5) - np.ceil(low / spacing - 0.5)).sum(axis=0)
    return CANDIDATE_ANGLES[int(np.argmin(crossings))]


class _Guard:
    """Where straight connectors may run (the area and a slack): whether the connector
    between two row ends stays inside, read for every pair of row ends a zigzag may link
    in one vectorised call (the same GEOS predicate on the same segments: the sliced
    cylinder's zigzags asked 67,000 times, one segment at a time)."""

    def __init__(self, area, rows, spacing: float) -> None:
        self.area = area
        shapely.prepare(area)
        pairs = [pair for r in range(len(rows) - 1) for x0, x1, y in rows[r]
                 for a, b, y_next in rows[r + 1] if y_next - y <= 1.5 * spacing
                 for pair in (((x1, y), (b, y_next)), ((x0, y), (a, y_next)))]
        covered = (shapely.covers(area, shapely.linestrings(np.asarray(pairs, dtype=float)))
                   if pairs else [])
        self._known = dict(zip(pairs, (bool(c) for c in covered)))

    def covers_link(self, p: tuple[float, float], q: tuple[float, float]) -> bool:
        known = self._known.get((p, q))
        return self.area.covers(LineString([p, q])) if known is None else known


class _Boundary:
    """The rings of an area (scan-line frame): paths along them between two boundary points."""

    def __init__(self, area) -> None:
        self.rings = []
        for poly in polygons_of(area):
            for ring in (poly.exterior, *poly.interiors):
                coords = np.asarray(ring.coords)
                along = np.concatenate(([0.0], np.cumsum(np.linalg.norm(np.diff(coords, axis=0), axis=1))))
                self.rings.append((LineString(coords), coords[:-1], along[:-1], float(along[-1])))
        #: point -> (distance to each ring, position along each ring), read in batches
        self._located: dict[tuple[float, float], tuple[np.ndarray, np.ndarray]] = {}

    def locate(self, points: list[tuple[float, float]]) -> None:
        """Read the rings' distance and position of many points in one GEOS call each (the
        same functions `path` would call one point at a time: CrankArm's zigzags asked
        34,000 times)."""
        if not points or not self.rings:
            return
        geometry = shapely.points(np.asarray(points, dtype=float))
        lines = np.array([line for line, *_ in self.rings], dtype=object)[:, None]
        distance = shapely.distance(lines, geometry[None, :])
        position = shapely.line_locate_point(lines, geometry[None, :])
        for k, point in enumerate(points):
            self._located[point] = (distance[:, k], position[:, k])

    def _where(self, point: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
        found = self._located.get(point)
        if found is None:
            geometry = shapely.Point(point)
            found = (np.array([line.distance(geometry) for line, *_ in self.rings]),
                     np.array([line.project(geometry) for line, *_ in self.rings]))
            self._located[point] = found
        return found

    def path(self, p: tuple[float, float], q: tuple[float, float],
             limit: float) -> list[tuple[float, float]] | None:
        """Points from p to q along the ring both lie on, the shorter way round, or None when
        they lie on no common ring or that way is longer than `limit`."""
        (p_distance, p_position), (q_distance, q_position) = self._where(p), self._where(q)
        for k, (_, vertices, along, length) in enumerate(self.rings):
            if p_distance[k] > ON_BOUNDARY or q_distance[k] > ON_BOUNDARY:
                continue
            start, end = float(p_position[k]), float(q_position[k])
            ahead = (end - start) % length
            way = min(ahead, length - ahead)
            if way > limit:
                return None
            offsets = (along - start) % length if ahead <= length - ahead else (start - along) % length
            inside = np.flatnonzero((offsets > 0.0) & (offsets < way))
            between = vertices[inside[np.argsort(offsets[inside])]]
            return [p, *map(tuple, between), q]
        return None


def zigzag(area, spacing: float, angle: float, width: float, role: str, phase: float = 0.5,
           line_width: float | None = None) -> list[Path2D]:
    """Scan lines at `spacing` along `angle` linked into zigzags: by a straight connector
    inside the area, else along its boundary when that is at most `LINK_ROWS` spacings
    (PrusaSlicer links its lines along the perimeter the same way)."""
    if area.is_empty:
        return []
    rows = _scan_segments(area, spacing, angle, phase)
    # Rows, connectors and boundary walks all in the scan-line frame (turned by -angle):
    # the guard was once the unturned area, so off the origin a connector could cross a
    # hole it was judged inside of.
    turned = affinity.rotate(area, -angle, origin=(0.0, 0.0), use_radians=True)
    guard = _Guard(turned.buffer(CONNECTOR_SLACK * width), rows, spacing)
    boundary = _Boundary(turned)
    # Links run between row ends only.
    boundary.locate([(x, y) for row in rows for x0, x1, y in row for x in (x0, x1)])
    used = [[False] * len(row) for row in rows]
    chains: list[list[tuple[float, float]]] = []
    for r, row in enumerate(rows):
        for s in range(len(row)):
            if used[r][s]:
                continue
            chain = _follow(rows, used, r, s, guard, boundary, spacing)
            chains.append(chain)
    cos, sin = math.cos(angle), math.sin(angle)
    paths = []
    for chain in chains:
        xy = np.asarray(chain)
        world = np.column_stack((xy[:, 0] * cos - xy[:, 1] * sin, xy[:, 0] * sin + xy[:, 1] * cos))
        paths.append(Path2D(world, role, width=line_width))
    return paths


def _follow(rows, used, r: int, s: int, guard: _Guard, boundary: _Boundary,
            spacing: float) -> list[tuple[float, float]]:
    """Walk from piece s of row r, alternating direction, onto the next row's nearest piece."""
    x0, x1, y = rows[r][s]
    used[r][s] = True
    chain = [(x0, y), (x1, y)]
    forward = True
    while r + 1 < len(rows):
        end_x, end_y = chain[-1]
        best, best_gap = None, LINK_ROWS * spacing
        for k, (a, b, y_next) in enumerate(rows[r + 1]):
            if used[r + 1][k] or y_next - end_y > 1.5 * spacing:
                continue
            near = b if forward else a
            gap = abs(near - end_x)
            if gap < best_gap:
                best, best_gap = k, gap
        if best is None:
            break
        a, b, y_next = rows[r + 1][best]
        start = (b, y_next) if forward else (a, y_next)
        if guard.covers_link(chain[-1], start):
            link = [start]
        else:
            link = boundary.path(chain[-1], start, LINK_ROWS * spacing)
            if link is None:
                break
            link = link[1:]
        used[r + 1][best] = True
        chain += [*link, (a, y_next) if forward else (b, y_next)]
        forward = not forward
        r += 1
    return chain


def _seam_index(ring: np.ndarray, seam: str, position: np.ndarray | None) -> int:
    points = ring[:-1]
    if seam == "nearest" and position is not None:
        return int(np.argmin(np.linalg.norm(points - position, axis=1)))
    if seam == "sharpest":
        before = points - np.roll(points, 1, axis=0)
        after = np.roll(points, -1, axis=0) - points
        turn = np.abs(np.arctan2(before[:, 0] * after[:, 1] - before[:, 1] * after[:, 0],
                                 np.einsum("ij,ij->i", before, after)))
        return int(np.argmax(turn))
    return int(np.lexsort((points[:, 0], -points[:, 1]))[0])


def start_ring_at(ring: np.ndarray, index: int) -> np.ndarray:
    """The closed ring re-started at vertex `index` (still closed)."""
    return np.concatenate((ring[index:-1], ring[:index + 1]))


def _nearest(candidates: list[Path2D], position: np.ndarray, reversible: bool) -> tuple[int, bool]:
    starts = np.array([p.points[0] for p in candidates])
    gaps = np.linalg.norm(starts - position, axis=1)
    if reversible:
        ends = np.array([p.points[-1] for p in candidates])
        back = np.linalg.norm(ends - position, axis=1)
        k = int(np.argmin(np.minimum(gaps, back)))
        return k, bool(back[k] < gaps[k])
    return int(np.argmin(gaps)), False


def nearest_first(paths: list[Path2D], here: np.ndarray | None) -> list[Path2D]:
    """Open paths in the order a nozzle at `here` (None: the first path's start) reaches
    them, each entered from its nearer end."""
    left, ordered = list(paths), []
    while left:
        if here is None:
            path = left.pop(0)
        else:
            k, flip = _nearest(left, here, reversible=True)
            path = left.pop(k)
            path = path.reversed() if flip else path
        ordered.append(path)
        here = path.points[-1]
    return ordered


#: Grid (mm) a region is snapped to when GEOS finds non-noded intersections in its
#: Booleans: a hundred-thousandth of a millimetre moves no bead, and on a fixed-precision
#: grid the overlay nodes every crossing.
SNAP_GRID = 1e-5


def _snapped(geometry):
    if geometry is None or geometry.is_empty:
        return geometry
    return valid_region(shapely.set_precision(geometry, SNAP_GRID))


def fill_layer(region, settings: FillSettings, layer_index: int = 0, solid=None,
               position: np.ndarray | None = None, height: float | None = None,
               bridge=None, air=None, anchors=None) -> list[Path2D]:
    """Ordered paths of one layer: per island, perimeters (innermost first) then infill.

    Args:
        region: the layer's section (shapely Polygon/MultiPolygon, layer coordinates).
        settings: bead width, perimeters, density, angle, seam.
        layer_index: parity picks the alternate infill direction.
        solid: area printed at 100 % (skins); None for none.
        position: the nozzle's position before the layer (seams "nearest", ordering).
        height: the layer's (mean) thickness, for the bead spacing; None: beads a width apart.
        bridge: part of `solid` filled apart as "bridge_infill", over sparse infill or
            over nothing (`paths.map3d.bridge_regions`); None for none.
        air: the part of `bridge` over nothing (`paths.map3d.air_at`), laid from anchor to
            anchor (`bridge_angle`); None for none.
        anchors: what carries its ends (the layer below); None: across its shortest span.
    """
    return ordered_fill(layer_fill(region, settings, layer_index, solid, height, bridge, air,
                                   anchors), settings, position)


@dataclass
class IslandFill:
    """One island's paths before they are ordered: its perimeter rings per depth (0 the
    external one), its infill chains and its beads along middles (thin walls and gap fill),
    laid after the rings. Nothing here depends on where the nozzle is, so a layer's fill
    can be made anywhere (`paths/stack_fill.py`) and ordered afterwards."""

    island: Polygon
    depths: list[list[np.ndarray]]
    infill: list[Path2D]
    beads: list[Path2D] = field(default_factory=list)
    #: the loops' bead width where widened (`island_walls`); None: the settings'
    ring_width: float | None = None


def layer_fill(region, settings: FillSettings, layer_index: int = 0, solid=None,
               height: float | None = None, bridge=None, air=None,
               anchors=None) -> list[IslandFill]:
    """The islands of one layer filled (`fill_layer`'s arguments), not yet ordered."""
    settings.validate()
    spacing = bead_spacing(settings.bead_width, height, settings.bead_model)
    # Offsets and scan lines of an invalid region (a self-touching section outline) raise
    # GEOS topology errors: repair first, so only what cannot be repaired is an error.
    islands = polygons_of(valid_region(region))
    solid = None if solid is None else valid_region(solid)
    bridge = None if bridge is None or bridge.is_empty else valid_region(bridge)
    air = None if air is None or air.is_empty or bridge is None else valid_region(air)
    filled = []
    for island in islands:
        try:
            fill = _island_fill(island, settings, spacing, layer_index, solid, bridge, air,
                                anchors)
        except shapely.errors.GEOSException:
            try:
                # Nearly coincident edges of the island and its skin (non-noded
                # intersections): the same on a fixed grid, where GEOS's overlay is robust.
                fill = _island_fill(_snapped(island), settings, spacing, layer_index,
                                    _snapped(solid), _snapped(bridge), _snapped(air), anchors)
            except shapely.errors.GEOSException as exc:
                raise PlanError(f"layer {layer_index}: the island at "
                                f"{island.representative_point().wkt} ({island.area:.3f} mm²) "
                                f"cannot be filled: {exc}") from None
        fill.island = island        # the island as given, also where its snapped copy was filled
        filled.append(fill)
    return filled


def ordered_fill(filled: list[IslandFill], settings: FillSettings,
                 position: np.ndarray | None = None) -> list[Path2D]:
    """A layer's paths in print order from the nozzle at `position`: islands nearest
    first; in each, its rings innermost depth first, each ring nearest first and started at
    its seam, then its thin-wall and gap-fill beads, then its infill chains, each nearest
    first from its nearer end (a closed bead from its nearest vertex)."""
    here = np.zeros(2) if position is None else np.asarray(position, dtype=float)
    islands = list(filled)
    ordered: list[Path2D] = []
    while islands:
        nozzle = shapely.Point(here)
        k = 0 if len(islands) == 1 else int(np.argmin([f.island.exterior.distance(nozzle)
                                                         for f in islands]))
        paths = _island_order(islands.pop(k), settings, here)
        ordered.extend(paths)
        if paths:
            here = paths[-1].points[-1]
    return ordered


def infill_areas(inner, solid, bridge, settings: FillSettings, spacing: float,
                 air=None, anchors=None) -> list[tuple[object, float, str, object, float | None]]:
    """(area the lines fill, row pitch, role, its part of the fill area, direction or None
    for the infill's own) of an island's infill inside its perimeters (`inner`, reaching
    `infill_overlap` into them: `fill_area`): solid where `solid` says
    and in sparse pieces under `solid_below_area`, the part of the solid filled as bridges
    (`bridge`) apart, its part over nothing (`air`) from anchor to anchor (`bridge_angle`
    with `anchors`, the layer below; else across its shortest span), the rest sparse. Each part is then shrunk by `LINE_END_INSET` of a
    spacing, where its lines end. Pieces are measured before that shrink, as PrusaSlicer
    measures its fill surfaces against solid_infill_below_area: measured after it, the
    screw head's 70-100 mm² islands turned solid where PrusaSlicer's stay sparse. The fill
    and the cost estimate (paths/cost.py) both split it here."""
    dense = inner.intersection(solid) if solid is not None and not solid.is_empty else Polygon()
    sparse = inner.difference(dense) if not dense.is_empty else inner
    small = [p for p in polygons_of(sparse) if p.area < settings.solid_below_area]
    if small and settings.density < 1.0:
        dense = dense.union(MultiPolygon(small))
        sparse = sparse.difference(MultiPolygon(small))
    over = spanned = Polygon()
    if bridge is not None and not bridge.is_empty and not dense.is_empty:
        over = dense.intersection(bridge)
        if not over.is_empty:
            dense = dense.difference(over)
        if air is not None and not over.is_empty:
            spanned = over.intersection(air)
            if not spanned.is_empty:
                over = over.difference(spanned)
    sparse_pitch = spacing / settings.density if settings.density > 0 else 0.0
    found = [(_line_area(dense, spacing), spacing, "solid_infill", dense, None),
             (_line_area(over, spacing), spacing, "bridge_infill", over, None)]
    if not spanned.is_empty:
        lines = _line_area(spanned, spacing)
        angle = None
        if not lines.is_empty:
            angle = (span_angle(lines, spacing) if anchors is None
                     else bridge_angle(lines, spacing, anchors, spacing))
        found.append((lines, spacing, "bridge_infill", spanned, angle))
    return found + [(_line_area(sparse, spacing), sparse_pitch, "infill", sparse, None)]


#: Solid lines are spread so that whole lines fill their area's width, each up to this much
#: wider than a spacing (PrusaSlicer's _adjust_solid_spacing: fewer lines, the same
#: material; on the screw's 8 mm shank one line in about forty).
SOLID_SPREAD_MAX = 1.2


@dataclass(frozen=True)
class Rows:
    """How an infill area's lines are laid: direction, pitch, grid phase (`scan_pieces`)
    and how much wider than the settings' their beads are."""

    angle: float
    pitch: float
    phase: float = 0.5
    wider: float = 0.0


def infill_rows(area, pitch: float, role: str, fill, settings: FillSettings, spacing: float,
                layer_index: int, angle: float | None = None) -> Rows:
    """The rows of one of `infill_areas`' parts (`area` where its lines end, `fill` its part
    of the fill area): the fewest-turns direction (or the given one), turned 90° on odd
    layers; solid and bridge lines, and infill at 100 % (PrusaSlicer's full infill), spread
    over their area (`solid_rows`), sparse lines on the global grid so they stack. The
    fill and the cost estimate (paths/cost.py) both lay rows by this. `angle`: the
    direction `infill_areas` gave the part (a bridge over nothing), kept on every layer."""
    if angle is None:
        angle = settings.angle if settings.angle is not None else fewest_turns_angle(area, pitch)
        if settings.alternate and layer_index % 2:
            angle += math.pi / 2
    if role in SOLID_ROLES or (role == "infill" and settings.density >= 1.0):
        spread, phase = solid_rows(fill, spacing, angle)
        return Rows(angle, spread, phase, spread - spacing)
    return Rows(angle, pitch)


def solid_rows(fill, spacing: float, angle: float) -> tuple[float, float]:
    """(row pitch, grid phase) of solid lines filling `fill` (its part of the fill area)
    at `angle`: as many whole spacings as fit its width across the lines, widened to span
    it (at most SOLID_SPREAD_MAX), the first row half a pitch inside."""
    low, high = _extent_across(fill, angle)
    across = high - low
    count = math.floor((across - ON_BOUNDARY) / spacing)
    if count < 1:
        return spacing, 0.5
    pitch = min(across / count, SOLID_SPREAD_MAX * spacing)
    return pitch, ((low + 0.5 * pitch) / pitch) % 1.0


def _extent_across(area, angle: float) -> tuple[float, float]:
    """(min, max) of `area` across scan lines along `angle` (the rotated frame's y)."""
    starts, _ = boundary_edges(area)
    y = -starts[:, 0] * math.sin(angle) + starts[:, 1] * math.cos(angle)
    return float(y.min()), float(y.max())


def fill_area(island: Polygon, depth_count: int, width: float, spacing: float,
              infill_overlap: float, filled: list[Polygon] | None = None):
    """What the infill of an island with `depth_count` perimeter rings fills: inside the
    innermost ring's centre line by half a spacing less `infill_overlap` of one (its beads
    then overlap the ring's by that share); the whole island without perimeters. Less the
    gaps inside the innermost rings that gap fill fills (`filled`, from `gap_fill`): grown
    by the same overlap, so no line reaches into them further than into a ring."""
    if not depth_count:
        return island
    depth = 0.5 * width + (depth_count - 0.5 - infill_overlap) * spacing
    area = inset(island, depth)
    if not filled or area.is_empty:
        return area
    with np.errstate(divide="ignore", invalid="ignore"):    # as in `inset`
        taken = MultiPolygon(filled).buffer(infill_overlap * spacing + GAP_CLEARANCE,
                                            join_style="mitre", mitre_limit=MITRE_LIMIT)
    return area.difference(taken)


#: Where a gap inside the innermost loops spans the fill area, the two share their outline
#: once the gap is grown by the infill overlap: grown this much (mm) further, no sliver of
#: fill area is left along it.
GAP_CLEARANCE = 1e-4


def _line_area(area, spacing: float):
    """Where lines filling `area` end (`LINE_END_INSET`)."""
    if area.is_empty:
        return area
    return inset(area, LINE_END_INSET * spacing)


def _island_fill(island: Polygon, settings: FillSettings, spacing: float, layer_index: int,
                 solid, bridge=None, air=None, anchors=None) -> IslandFill:
    """Perimeter rings per depth, infill chains and thin-wall and gap-fill beads of one
    island."""
    width = settings.bead_width
    external = inset(island, 0.5 * width)
    walls = island_walls(island, width, settings.perimeters, spacing, external)
    depths = walls.depths
    ring_width = None if walls.width == width else walls.width
    gap_paths, filled = gap_fill(walls, settings, spacing)
    beads = thin_wall_paths(island, settings, external) + gap_paths
    infill: list[Path2D] = []
    inner = fill_area(island, len(depths), walls.width, walls.spacing, settings.infill_overlap,
                      filled)
    if inner.is_empty:
        return IslandFill(island, depths, infill, beads, ring_width)
    for area, pitch, role, fill, angle in infill_areas(inner, solid, bridge, settings, spacing,
                                                       air, anchors):
        if area.is_empty or pitch <= 0 or area.area < width * width:
            continue
        rows = infill_rows(area, pitch, role, fill, settings, spacing, layer_index, angle)
        # The bead that fills the wider pitch of spread rows.
        line_width = width + rows.wider if rows.wider else None
        infill += zigzag(area, rows.pitch, rows.angle, width, role, rows.phase, line_width)
    return IslandFill(island, depths, infill, beads, ring_width)


def thin_wall_paths(island: Polygon, settings: FillSettings, external) -> list[Path2D]:
    """One external-perimeter bead along each feature of the island narrower than a bead
    (`paths/thin_walls.py`; `external`: the island inset by half a bead), as wide as the
    feature; none without perimeters."""
    if not settings.perimeters:
        return []
    return [Path2D(points, "external_perimeter", closed, bead)
            for points, bead, closed in thin_wall_beads(island, settings.bead_width, external,
                                                        MITRE_LIMIT)]


def gap_fill(walls: Walls, settings: FillSettings,
             spacing: float) -> tuple[list[Path2D], list[Polygon]]:
    """One bead along each gap the perimeter loops leave (`Walls`,
    `paths/thin_walls.gap_beads`), as wide as fills it, pieces whose ends meet joined
    (`thin_walls.joined_beads`), and the gaps inside the innermost loops that got one (the
    infill leaves those; a piece too short for a bead stays the infill's). Laid as inner
    perimeters (their speed): the gaps lie between loops."""
    beads = []
    filled: list[Polygon] = []
    for gap, inside in [(gap, False) for gap in walls.gaps] + [(gap, True) for gap in walls.interior]:
        found = gap_beads([gap], settings.bead_width, spacing)
        beads += found
        if found and inside:
            filled.append(gap)
    paths = [Path2D(points, "perimeter", closed, bead)
             for points, bead, closed in joined_beads(beads, settings.bead_width)]
    return paths, filled


def _island_order(filled: IslandFill, settings: FillSettings, here: np.ndarray) -> list[Path2D]:
    paths: list[Path2D] = []
    for depth in reversed(range(len(filled.depths))):
        role = "external_perimeter" if depth == 0 else "perimeter"
        rings = list(filled.depths[depth])
        while rings:
            k = 0 if len(rings) == 1 else int(np.argmin([np.min(np.linalg.norm(r - here, axis=1))
                                                         for r in rings]))
            ring = rings.pop(k)
            ring = start_ring_at(ring, _seam_index(ring, settings.seam, here))
            paths.append(Path2D(ring, role, closed=True, width=filled.ring_width))
            here = ring[-1]
    for path in _ordered_beads(filled.beads, here):
        paths.append(path)
        here = path.points[-1]
    return paths + nearest_first(filled.infill, here)


def _ordered_beads(beads: list[Path2D], here: np.ndarray) -> list[Path2D]:
    """An island's thin-wall and gap-fill beads nearest first from `here`: a closed gap
    bead from its nearest vertex (it shows no seam: it lies between loops), any other from
    its nearer end (a closed thin wall keeps its start: its seam is on the surface)."""
    left, ordered = list(beads), []
    while left:
        near = [np.min(np.linalg.norm(b.points - here, axis=1)) if _entered_anywhere(b)
                else min(np.linalg.norm(b.points[0] - here), np.linalg.norm(b.points[-1] - here))
                for b in left]
        path = left.pop(int(np.argmin(near)))
        if _entered_anywhere(path):
            start = int(np.argmin(np.linalg.norm(path.points[:-1] - here, axis=1)))
            path = Path2D(start_ring_at(path.points, start), path.role, path.closed, path.width)
        elif np.linalg.norm(path.points[-1] - here) < np.linalg.norm(path.points[0] - here):
            path = path.reversed()
        ordered.append(path)
        here = path.points[-1]
    return ordered


def _entered_anywhere(bead: Path2D) -> bool:
    """Whether a bead may start at any of its vertices: one inside the part (not a thin
    wall) that ends where it starts (closed, or gap pieces joined round a loop, which stay
    open for their feed: `thin_walls.joined_beads`)."""
    return (bead.role != "external_perimeter" and len(bead.points) > 2
            and float(np.linalg.norm(bead.points[-1] - bead.points[0])) <= COINCIDENT_POINTS)
