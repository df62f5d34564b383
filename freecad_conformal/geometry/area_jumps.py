"""Area-jump split planes (METHODS section 4): the fallback when no splitting face qualifies.

Sections every `d` mm along ±X, ±Y, ±Z; where the exact section area jumps,
∂ = (S(i+1) − S(i)) / d > 1 (the published rule, on raw areas), a cut between the two
sections is proposed. The cut is restricted, as for splitting faces, to the interior regions
of the plane's section; the decomposition keeps it only if it saves overhang.

The areas are exact (OCC sections) by default. `exact=False` reads them from a fine
triangulation instead, ~8x faster on B-spline parts: the section area at h is minus the
projection on the axis of the boundary below h (divergence theorem), summed over the
triangles clipped at h. The decomposition uses it only to propose planes; the cut along a
proposed plane is exact. On CrankArm it finds the same jumps as the exact sections.
"""
from __future__ import annotations

import numpy as np

from freecad_conformal.errors import GeometryError
from freecad_conformal.geometry.face_normals import plane_normal
from freecad_conformal.geometry.frames import index_rows, points_array
from freecad_conformal.geometry.sections import PlanarSlicer, extent_along
from freecad_conformal.geometry.shape_parts import vertex_points
from freecad_conformal.geometry.splitting_faces import SplitCandidate, interior_regions
from freecad_conformal.geometry.surface_mesh import (mesh_deflection, sorted_below_fraction,
                                                    surface_mesh)
from freecad_conformal.tolerances import PARALLEL_COS_SLACK

#: Sections per axis when `d` is not given (the jump test only needs to see the steps).
DEFAULT_SLICES = 40

#: The published threshold on ∂ (mm² per mm).
JUMP_THRESHOLD = 1.0

AXES = tuple(np.array(v, dtype=float) for v in np.vstack([np.eye(3), -np.eye(3)]))


def _area_profile(shape, axis: np.ndarray, d: float | None) -> tuple[np.ndarray, np.ndarray, float]:
    """Exact section areas along `axis` (one batch of sections): heights, areas, step."""
    low, high = extent_along(shape, axis)
    step = d if d is not None else (high - low) / DEFAULT_SLICES
    if step <= 0:
        return np.zeros(0), np.zeros(0), 0.0
    heights = np.arange(low + step / 2, high, step)
    if len(heights) < 2:
        return heights, np.zeros(len(heights)), step
    try:
        slicer = PlanarSlicer(shape, axis)
    except GeometryError:
        # A piece left by an earlier Boolean that OCC's check rejects: it gets no area-jump
        # planes (its splitting faces are still tried), rather than stopping the plan.
        return np.zeros(0), np.zeros(0), 0.0
    areas = np.array([s.area for s in slicer.sections(list(heights))])
    return heights, areas, step


class MeshProfile:
    """Section areas of a solid along any axis from one triangulation of its boundary."""

    def __init__(self, shape) -> None:
        mesh = surface_mesh(shape)  # the decomposition's trial cuts read the same mesh
        if mesh is not None:
            self.points, self.triangles = mesh.points, mesh.triangles
        else:
            deflection = mesh_deflection(shape)
            # On a copy: re-meshing the shape itself would undo the surface mesh's sharing.
            points, triangles = shape.copy().tessellate(deflection, True)
            self.points = points_array(points)
            self.triangles = index_rows(triangles)
        a, b, c = (self.points[self.triangles[:, k]] for k in range(3))
        #: each triangle's area vector (outward normal × area)
        self.area_vectors = 0.5 * np.cross(b - a, c - a)

    def areas(self, axis: np.ndarray, heights: np.ndarray) -> np.ndarray:
        """Section area at each height along `axis`: A(h) = −Σ (n·axis) area(t ∩ {x·axis < h})."""
        projected = self.area_vectors @ axis
        g = np.sort((self.points @ axis)[self.triangles], axis=1)
        g0, g1, g2 = (np.ascontiguousarray(g[:, k]) for k in range(3))
        # Triangles wholly below h count whole: a prefix sum over them sorted by their top
        # corner; only those h crosses are clipped (Pump_Nut: 4 ms per height over all
        # 17,500 triangles, a few hundred crossed).
        order = np.argsort(g2, kind="stable")
        tops = g2[order]
        below = np.concatenate(([0.0], np.cumsum(projected[order])))
        result = np.zeros(len(heights))
        for k, h in enumerate(heights):
            crossed = np.flatnonzero((g0 < h) & (g2 >= h))
            clipped = sorted_below_fraction(g0[crossed] - h, g1[crossed] - h, g2[crossed] - h)
            whole = below[np.searchsorted(tops, h, side="left")]
            result[k] = -(float(whole) + float(projected[crossed] @ clipped))
        return result


def _mesh_area_profile(mesh: MeshProfile, extent: tuple[float, float], axis: np.ndarray,
                       d: float | None):
    low, high = extent
    step = d if d is not None else (high - low) / DEFAULT_SLICES
    if step <= 0:
        return np.zeros(0), np.zeros(0), 0.0
    heights = np.arange(low + step / 2, high, step)
    return heights, mesh.areas(axis, heights), step


def _jumps(heights: np.ndarray, areas: np.ndarray, step: float) -> list[tuple[float, float]]:
    if len(heights) < 2:
        return []
    rates = np.diff(areas) / step
    return [(float(heights[i] + step / 2), float(rates[i]))
            for i in np.nonzero(rates > JUMP_THRESHOLD)[0]]


def area_jumps(shape, direction: np.ndarray, d: float | None = None) -> list[tuple[float, float]]:
    """(height between the two sections, ∂) for each jump with ∂ > 1 along `direction`."""
    heights, areas, step = _area_profile(shape, np.asarray(direction, dtype=float), d)
    return _jumps(heights, areas, step)


def area_jump_planes(shape, build_direction: np.ndarray, d: float | None = None,
                     limit: int = 12, skip=None,
                     exact: bool = True) -> list[tuple[float, np.ndarray, np.ndarray]]:
    """(∂, point, normal) of the planes of the largest area jumps along ±X, ±Y, ±Z (the
    build direction itself excluded: a cut across it changes nothing), largest first.

    One batch of sections per axis serves both signs: along −X the same areas are read in
    the opposite order, at negated heights. `skip(axis)` true leaves an axis out before its
    sections are cut (a caller that knows no plane across it can help). `exact=False` reads
    the areas from a triangulation (see the module docstring).
    """
    jumps = []
    mesh = None if exact else MeshProfile(shape)
    for axis in AXES[:3]:
        if abs(float(axis @ build_direction)) > 1 - 1e-9:
            continue
        if skip is not None and skip(axis):
            continue
        if mesh is None:
            heights, areas, step = _area_profile(shape, axis, d)
        else:
            # Exact extents (OCC's extrema, whatever the shape's triangulation): the heights
            # are those the exact sections would use.
            heights, areas, step = _mesh_area_profile(mesh, extent_along(shape, axis), axis, d)
        levels = _face_levels(shape, axis)
        # Along +axis a jump's plane sits at height h (x·axis = h); along −axis the same areas
        # are read backwards at heights −h, and its point is (−axis)·(−h): the same place.
        jumps.extend((rate, _snap(height, step, levels), axis)
                     for height, rate in _jumps(heights, areas, step))
        jumps.extend((rate, -_snap(-height, step, levels), -axis)
                     for height, rate in _jumps(-heights[::-1], areas[::-1], step))
    jumps.sort(key=lambda item: -item[0])
    return [(rate, axis * height, axis) for rate, height, axis in jumps[:limit]]


def _face_levels(shape, axis: np.ndarray) -> np.ndarray:
    """Heights along `axis` of the shape's planar faces perpendicular to it: where a section's
    area can jump (the underside of a cap, the top of a column)."""
    levels = []
    for face in shape.Faces:
        surface = face.Surface
        if type(surface).__name__ == "Plane":
            normal = np.array(tuple(surface.Axis), dtype=float)
            on_plane = np.array(tuple(surface.Position), dtype=float)
        else:
            # A plane written as a B-spline (lofts, exporters, `toNurbs`): its planes
            # landed on the sampling grid, 0.25 mm into the column under a cap.
            normal = plane_normal(face)
            if normal is None:
                continue
            on_plane = vertex_points(face)[0]
        if abs(abs(float(normal @ axis)) - 1.0) < PARALLEL_COS_SLACK:
            levels.append(float(on_plane @ axis))
    return np.array(levels)


def _snap(height: float, step: float, levels: np.ndarray) -> float:
    """The jump between the two sections around `height` happens at a face level inside that
    interval when there is one: the plane goes there (the nearest), not onto the sampling
    grid's midpoint, which may cut through the member the jump belongs to."""
    inside = levels[np.abs(levels - height) <= step / 2]
    if len(inside) == 0:
        return height
    return float(inside[np.argmin(np.abs(inside - height))])


def plane_candidates(shape, point: np.ndarray, normal: np.ndarray) -> list[SplitCandidate]:
    """The interior regions of one area-jump plane, as cut candidates."""
    return [SplitCandidate(point, normal, region, "area-jump")
            for region in interior_regions(shape, point, normal)]


def area_jump_candidates(shape, build_direction: np.ndarray, d: float | None = None,
                         limit: int = 12) -> list[SplitCandidate]:
    """Interior regions on the planes of the largest area jumps (see `area_jump_planes`)."""
    candidates: list[SplitCandidate] = []
    for _, point, axis in area_jump_planes(shape, build_direction, d, limit):
        candidates.extend(plane_candidates(shape, point, axis))
    return candidates
