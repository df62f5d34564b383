"""Planar fills for feature and mandrel paths: zigzag (boustrophedon) and contours (shapely).

Pure numpy + shapely. A fill returns polylines ((N, 2) arrays); consecutive points of one
polyline are joined by a deposit/cure move, separate polylines by a travel. Zigzag lines are
straight, so after mapping onto a developable surface (cylinder, cone) each line stays one
"linear in joints" move.
"""
from __future__ import annotations

import math

import numpy as np
import shapely
from shapely import affinity
from shapely.geometry import LineString, MultiPolygon, Polygon

from freecad_conformal.errors import PlanError

#: A connector between two zigzag lines may leave the region by this much (mm): connectors
#: run along the inset boundary, which the polygonised region only approximates.
CONNECT_SLACK = 1e-6

#: Pieces of scan lines shorter than this fraction of the spacing are dropped: they are
#: tangent touches of the region, not lines a bead can draw.
MIN_LINE_FRACTION = 0.05

#: The outer scan rows are kept this fraction of their margin inside the inset boundary, so
#: a row is not lost to rounding where it would touch the shrunk region tangentially.
EDGE_FRACTION = 0.999


def _polygons(region) -> list[Polygon]:
    if region.is_empty:
        return []
    if isinstance(region, Polygon):
        return [region]
    return [g for g in getattr(region, "geoms", []) if isinstance(g, Polygon) and not g.is_empty]


def long_axis_angle(region) -> float:
    """Direction (rad) of the long side of the region's minimum rotated rectangle: rasters
    along it give the fewest, longest lines (a helical band's inclination α)."""
    rectangle = shapely.minimum_rotated_rectangle(region)
    coords = np.asarray(rectangle.exterior.coords)[:4]
    sides = np.diff(np.vstack((coords, coords[:1])), axis=0)[:2]
    longest = sides[int(np.argmax(np.linalg.norm(sides, axis=1)))]
    return float(math.atan2(longest[1], longest[0]))


def zigzag(region, spacing: float, angle: float = 0.0, inset: float | None = None,
           what: str = "region") -> list[np.ndarray]:
    """Boustrophedon fill of `region` (shapely polygon(s)) with lines at `angle` (rad),
    `spacing` apart. The line count across each polygon is its width / spacing rounded (so
    beads of width `spacing` fill it, within half a bead; none under half a bead), centred; line ends stay `inset`
    (default spacing/2) inside the boundary. Raises PlanError if nothing fits.
    """
    if not spacing > 0:
        raise PlanError(f"{what}: line spacing must be > 0 mm, got {spacing!r}")
    inset = spacing / 2.0 if inset is None else inset
    paths: list[np.ndarray] = []
    for polygon in _polygons(region):
        paths.extend(_zigzag_polygon(polygon, spacing, angle, inset))
    if not paths:
        raise PlanError(f"{what} is too thin for one line {spacing:g} mm wide "
                        f"(area {region.area:.4g} mm²)")
    return paths


def _zigzag_polygon(polygon: Polygon, spacing: float, angle: float, inset: float) -> list[np.ndarray]:
    origin = polygon.centroid
    turned = affinity.rotate(polygon, -angle, origin=origin, use_radians=True)
    x0, y0, x1, y1 = turned.bounds
    count = int(round((y1 - y0) / spacing))
    if count == 0:
        return []             # thinner than half a bead: no line belongs there
    margin = 0.5 * ((y1 - y0) - (count - 1) * spacing)
    # the outer rows sit `margin` from the extremes: shrink no further or they vanish
    inner = turned.buffer(-min(inset, EDGE_FRACTION * margin)) if inset > 0 else turned
    if inner.is_empty:
        return []
    rows: list[list[tuple[float, float]]] = []
    for k in range(count):
        y = y0 + margin + k * spacing
        cut = inner.intersection(LineString([(x0 - 1.0, y), (x1 + 1.0, y)]))
        pieces = sorted(((min(a, b), max(a, b)) for a, b in _x_ranges(cut)
                         if abs(b - a) >= MIN_LINE_FRACTION * spacing))
        rows.append(pieces)
    lines = _chain(rows, y0 + margin, spacing, inner.buffer(CONNECT_SLACK))
    back = []
    for line in lines:
        rotated = affinity.rotate(LineString(line), angle, origin=origin, use_radians=True)
        back.append(np.asarray(rotated.coords))
    return back


def _x_ranges(cut) -> list[tuple[float, float]]:
    out = []
    for geom in getattr(cut, "geoms", [cut]):
        if isinstance(geom, LineString) and not geom.is_empty:
            xs = [c[0] for c in geom.coords]
            out.append((min(xs), max(xs)))
    return out


def _chain(rows: list[list[tuple[float, float]]], offset: float, spacing: float,
           region) -> list[list[tuple[float, float]]]:
    """Join scan pieces row by row into as few polylines as possible, alternating direction,
    when the connector stays inside the region."""
    remaining = [list(r) for r in rows]
    lines = []
    while any(remaining):
        k = next(i for i, r in enumerate(remaining) if r)
        a, b = remaining[k].pop(0)
        y = offset + k * spacing
        line = [(a, y), (b, y)]
        forward = True
        while k + 1 < len(remaining) and remaining[k + 1]:
            end_x = line[-1][0]
            ny = offset + (k + 1) * spacing
            options = sorted(remaining[k + 1], key=lambda p: min(abs(p[0] - end_x), abs(p[1] - end_x)))
            joined = False
            for piece in options:
                start, stop = (piece[1], piece[0]) if forward else (piece[0], piece[1])
                if region.covers(LineString([line[-1], (start, ny)])):
                    remaining[k + 1].remove(piece)
                    line += [(start, ny), (stop, ny)]
                    joined = True
                    break
            if not joined:
                break
            forward = not forward
            k += 1
        lines.append(line)
    return lines


def contours(region, spacing: float, count: int | None = None,
             what: str = "region") -> list[np.ndarray]:
    """Concentric closed loops `spacing` apart, the first spacing/2 inside the boundary;
    `count` loops at most (None: until the region is filled). Outer loops first."""
    if not spacing > 0:
        raise PlanError(f"{what}: line spacing must be > 0 mm, got {spacing!r}")
    loops: list[np.ndarray] = []
    distance = spacing / 2.0
    while count is None or len(loops) < count:
        shrunk = region.buffer(-distance, join_style="mitre")
        polygons = _polygons(shrunk)
        if not polygons:
            break
        for polygon in polygons:
            loops.append(np.asarray(polygon.exterior.coords))
            loops.extend(np.asarray(ring.coords) for ring in polygon.interiors)
        distance += spacing
    if not loops:
        raise PlanError(f"{what} is too thin for one line {spacing:g} mm wide "
                        f"(area {region.area:.4g} mm²)")
    return loops


def as_region(polygons) -> MultiPolygon | Polygon:
    """A valid shapely region from polygons (repairing self-touching rings)."""
    region = shapely.make_valid(shapely.union_all(list(polygons)))
    return region
