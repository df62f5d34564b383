"""Which points lie inside a solid, many at once.

OCC's classifier (`Shape.isInside`) is exact but builds itself anew on every call: tens of
µs on a block, several ms on a free-form part (the bottle in ../shared/parts: 7 ms), and a
material check asks it tens of thousands of times. `MeshInside` counts, for every point at
once, the crossings of a vertical ray with the solid's fine tessellation (odd: inside),
with the triangles binned on an XY grid. Its answer can differ from the exact one only
within the tessellation's deflection of the surface.

`inside_test(solid)` gives the exact classifier where it is cheap and the mesh where it
is not. `RayGrid` serves other rays along one direction too (support columns,
`geometry/support.py`).
"""
from __future__ import annotations

import time

import numpy as np

#: Chord deflection (mm) of the tessellation: the band about the surface where the mesh's
#: answer may differ from the exact one, a fifth of the 0.05 mm finishing tolerance.
DEFLECTION = 0.01

#: Above this many seconds per exact classification the mesh is used instead.
EXACT_BUDGET = 2e-4

#: Points whose XY lands exactly on a triangle's edge would count it twice or not at all;
#: every ray is moved this far (mm) in an irrational direction instead.
NUDGE = 1e-7 * np.array([0.5 ** 0.5, 3.0 ** -0.5])


class RayGrid:
    """Triangles (m, 3, 3) binned on a grid across `axis`, for rays along it: which
    triangles a ray through a point crosses, and at what height along the axis."""

    def __init__(self, triangles: np.ndarray, axis=(0.0, 0.0, 1.0)) -> None:
        n = np.asarray(axis, dtype=float)
        n = n / np.linalg.norm(n)
        seed = np.eye(3)[int(np.argmin(np.abs(n)))]
        u = seed - (seed @ n) * n
        u /= np.linalg.norm(u)
        self.basis = np.stack([u, np.cross(n, u), n])          # rows: u, v, n
        self.triangles = np.asarray(triangles, dtype=float) @ self.basis.T
        uv = self.triangles[:, :, :2]
        low, high = uv.min(axis=1), uv.max(axis=1)
        self.origin = low.min(axis=0)
        # cells about four times a typical triangle's footprint
        footprint = float(np.median(np.maximum(high - low, 1e-6).max(axis=1)))
        self.cell = max(4.0 * footprint, 1e-3)
        first = np.floor((low - self.origin) / self.cell).astype(np.int64)
        last = np.floor((high - self.origin) / self.cell).astype(np.int64)
        self.columns = int(last[:, 1].max()) + 1
        spans = last - first + 1
        counts = spans[:, 0] * spans[:, 1]
        tri = np.repeat(np.arange(len(first)), counts)
        within = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
        keys = (first[tri, 0] + within // spans[tri, 1]) * self.columns \
            + first[tri, 1] + within % spans[tri, 1]
        order = np.argsort(keys, kind="stable")
        self.keys, self.cell_triangles = keys[order], tri[order]

    def crossings(self, points: np.ndarray, chunk_pairs: int = 2_000_000):
        """Yield (owner, height, point height) for every triangle the line along the axis
        through each point (n, 3) crosses: `owner` indexes `points`."""
        local = np.asarray(points, dtype=float).reshape(-1, 3) @ self.basis.T
        if not len(local):
            return
        uv = local[:, :2] + NUDGE
        cell = np.floor((uv - self.origin) / self.cell).astype(np.int64)
        valid = (cell >= 0).all(axis=1) & (cell[:, 1] < self.columns)
        keys = np.where(valid, cell[:, 0] * self.columns + cell[:, 1], -1)
        start = np.searchsorted(self.keys, keys, side="left")
        counts = np.where(valid, np.searchsorted(self.keys, keys, side="right") - start, 0)
        step = max(1, chunk_pairs // max(1, int(counts.mean()) + 1))
        for a in range(0, len(local), step):
            b = min(a + step, len(local))
            n = counts[a:b]
            owner = np.repeat(np.arange(a, b), n)
            pos = np.repeat(start[a:b], n) + (np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n))
            tri = self.triangles[self.cell_triangles[pos]]
            covered, height = _covering(tri, uv[owner])
            yield owner[covered], height[covered], local[owner[covered], 2]


class MeshInside:
    """Point-in-solid by ray parity against the tessellation of `solid`."""

    def __init__(self, solid, deflection: float = DEFLECTION) -> None:
        vertices, faces = solid.tessellate(deflection)
        v = np.array([tuple(p) for p in vertices], dtype=float)
        self.grid = RayGrid(v[np.array(faces, dtype=np.int64).reshape(-1, 3)])

    def __call__(self, points: np.ndarray) -> np.ndarray:
        """(n,) whether each point (n, 3) is inside the solid."""
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        crossings = np.zeros(len(points), dtype=np.int64)
        for owner, height, z in self.grid.crossings(points):
            crossings += np.bincount(owner[height > z], minlength=len(points))
        return crossings % 2 == 1


def first_hits_below(grid: RayGrid, points: np.ndarray) -> np.ndarray:
    """Distance (mm) from each point down the grid's axis to the first triangle (inf if
    none)."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    out = np.full(len(points), np.inf)
    for owner, height, z in grid.crossings(points):
        below = height < z
        np.minimum.at(out, owner[below], (z - height)[below])
    return out


def _covering(tri: np.ndarray, uv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Whether each triangle (k, 3, 3; grid coordinates) covers its point's (u, v) (k, 2),
    and the triangle's height there."""
    p0, p1, p2 = tri[:, 0], tri[:, 1], tri[:, 2]
    d1 = p1[:, :2] - p0[:, :2]
    d2 = p2[:, :2] - p0[:, :2]
    r = uv - p0[:, :2]
    det = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    ok = np.abs(det) > 1e-18
    safe = np.where(ok, det, 1.0)
    s = (r[:, 0] * d2[:, 1] - r[:, 1] * d2[:, 0]) / safe
    t = (d1[:, 0] * r[:, 1] - d1[:, 1] * r[:, 0]) / safe
    inside = ok & (s >= 0) & (t >= 0) & (s + t <= 1)
    return inside, p0[:, 2] + s * (p1[:, 2] - p0[:, 2]) + t * (p2[:, 2] - p0[:, 2])


def inside_test(solid, budget: float = EXACT_BUDGET):
    """A function (points (n, 3), on_surface_inside: bool) -> (n,) bool: OCC's exact
    classifier when a trial call takes at most `budget` seconds, else `MeshInside` (which
    cannot tell points on the surface apart and ignores the flag)."""
    from freecad_conformal.freecad_env import import_freecad

    App, _ = import_freecad()
    probe = App.Vector(solid.BoundBox.Center)
    if _quickest_call(lambda: solid.isInside(probe, 1e-6, True)) <= budget:
        def exact(points: np.ndarray, on_surface: bool) -> np.ndarray:
            return np.array([solid.isInside(App.Vector(*p), 1e-6, on_surface) for p in points],
                            dtype=bool)
        return exact
    mesh = MeshInside(solid)
    return lambda points, on_surface: mesh(points)


def _quickest_call(call, trials: int = 5) -> float:
    """The least of `trials` timed calls (s): the call's own cost, as free as a busy
    machine allows of time lost to other processes (which only ever adds)."""
    best = float("inf")
    for _ in range(trials):
        start = time.perf_counter()
        call()
        best = min(best, time.perf_counter() - start)
    return best
