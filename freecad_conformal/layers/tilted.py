"""3-D layers: section planes that tilt to follow a bending centroidal axis (METHODS section 3).

From the current plane (point C_low, the section's centroid, normal D_low) the local axis
direction D_up points at the centroid of the section Δ further along D_low. The next plane
passes through C_low + Δ·D_up with normal D_up. If the slab between the planes is thinner
than ΔL_min or thicker than ΔL_max anywhere over the section, D_up is bisected towards
D_low (D_up ← (D_up + D_low)/2) until it fits or the two are within `PARALLEL_ANGLE`; then
Δ shrinks by a quarter and the search repeats. A slab that cannot fit even at ΔL_min is
refused with a PlanError naming the layer and its thickness range.

Robustness: planes a hair off the build direction meet the faces square to it (a boss's
top, a step) almost tangentially, and OCC's section wires then come out degenerate (their
discretization ran away to 24 GB or aborted the process on CrankArm). Tilts accumulate
over a stack (0.15° one way, 0.149° back), so every normal within `PARALLEL_ANGLE` of the
build direction snaps to it exactly.

Cost: each tilted plane is its own OCC Boolean (planar layers share one per 32 planes), so
a trial plane is first checked against the lower section's boundary alone (numpy: the
slab's thickness over the lower section), and cut only when that fits; a layer then costs
about three cuts (the probe, the upper plane, the middle plane; the middle ones on a
second core while the chain goes on, `geometry/plane_stream.py`). Slicers are kept for the
last few normals only, so a long bend does not hold one slicer per layer.

The probe is a cut of its own, and both cheaper ways to read the axis were measured wrong:
the chord from the last plane's centroid (no probe: the pipe elbow's layers 30 % faster)
wobbles where the section changes shape, as centroids on planes of different tilt are not
on one axis (branch55's planes swung between 2.2° and 3.3° for 14 layers, where the probe
turns them steadily to 20°); and the drift between two sections of the part's mesh 0.2 mm
apart is 1-3° off on the elbow, whose triangles run 4 mm along the bend. Centroids come
from the section's polygons in its own frame; a section without a finite centroid (a
plane grazing a face) ends the tilted stack there instead of passing NaN on.
"""
from __future__ import annotations

import math
from collections import OrderedDict

import numpy as np
from shapely import affinity
from shapely.geometry import MultiPolygon

from freecad_conformal.errors import PlanError
from freecad_conformal.geometry.frames import angle_between, unit
from freecad_conformal.geometry.plane_stream import PlaneStream
from freecad_conformal.geometry.sections import PlanarSection, PlanarSlicer, highest_along
from freecad_conformal.layers.model import (BOUNDARY_INSET, SHRINK, Layer, LayerSettings,
                                            as_multipolygon)
from freecad_conformal.decomposition.subparts import SubPart

#: Window (mm along the axis) over which centroid drift is measured to tell a bend: short
#: enough to see a bend of a few centimetres' radius, long enough to smooth polygon noise.
BEND_WINDOW = 2.0

#: The axis bends when the drift over the window leans this much from the build direction;
#: below 3° tilting gains nothing a planar layer does not already print support-free.
BEND_MIN_ANGLE = math.radians(3.0)

#: Drift leaning more than 70° is a jump of the centroid (a column on a wider base, a
#: sudden change the decomposition splits at: 5.5 mm sideways over the 2 mm window), not a
#: bend to follow. Leans past the 45° overhang rule are the ones planar layers cannot
#: print, so the planes must follow them (at 45° here a branch leaning 55° got planar
#: layers and 1,228 mm³ of support; followed, 72 mm³; no plan of the parts in
#: ../shared/parts changed).
BEND_MAX_ANGLE = math.radians(70.0)

#: A window whose area changes by more than this ratio is a geometric change, not a bend.
BEND_AREA_RATIO = 1.25

#: A bent bar's section moves with its centroid and changes shape only slowly (its planar
#: section stretches as 1/cos of the lean: 2 mm along a 25 mm radius changes it by a few
#: per cent); a section whose moved copy misses the next one by more than this fraction of
#: its area grew or shrank on one side instead.
BEND_SHAPE_CHANGE = 0.1

#: And the move must explain the change: the moved copy misses the next section by at most
#: this share of what the unmoved one misses. A bend moves the section (the pipe elbow 0.18,
#: the connecting rod 0.29, branch45 0.47, an inclined rod 0); a side that grows moves the
#: centroid too, yet moving the section there misses more than leaving it (the fan's blades
#: seen along its hub 1.12, a pedestal on an ellipsoid's side 1.42), as does a square lofted
#: into a circle (1.0). Those passed the 10 % above, whose measure is the whole section's
#: area, and got 3-D layers that follow no axis: 7 of the fan's 22 s plan choice.
BEND_MOVE_SHARE = 0.7

#: A bend leans the axis over three windows running, to the same side (their sideways
#: drifts within 60°): a step aside (a thread's end, a boss) moves the centroid over two
#: windows at most, or back (a modelled M10 thread's ends made 51 of its 73 layers 3-D,
#: three OCC cuts each: 51 of its 94 s of planning, for planes that wobble where the part
#: is straight).
BEND_SAME_SIDE_COS = 0.5
BEND_WINDOWS = 3

#: The least turn per layer worth tilting for: ten layers to follow the gentlest bend
#: worth following (`BEND_MIN_ANGLE`).
MIN_TURN = BEND_MIN_ANGLE / 10.0

#: Planes closer than this angle count as parallel: bisection stops there (METHODS' ε).
PARALLEL_ANGLE = math.radians(0.1)

#: Bisections needed to go from 90° to `PARALLEL_ANGLE` (90° / 2^k < 0.1°), plus the
#: final parallel try and margin.
MAX_BISECTIONS = 14

#: Slicers kept (one per plane normal): the probe and the lower plane share the current
#: normal, a trial plane brings a new one; older ones are not reused.
SLICER_CACHE = 4


def turn_capacity(layer: Layer, d_min: float, d_max: float) -> float:
    """The largest turn (rad) of the next plane about the layer's centroid that keeps the
    slab within [ΔL_min, ΔL_max] over the layer's region (its farthest boundary point)."""
    centre = np.array(layer.region.centroid.coords[0])
    points = np.vstack([np.asarray(poly.exterior.coords) for poly in layer.region.geoms])
    reach = float(np.linalg.norm(points - centre, axis=1).max())
    slack = min(d_max - layer.thickness, layer.thickness - d_min)
    if slack <= 0:
        return 0.0
    return math.atan2(slack, reach)


def layer_centroids(layers: list[Layer]) -> np.ndarray:
    """(L, 3): each layer's region centroid, in 3-D."""
    return np.array([layer.to_3d(np.array([layer.region.centroid.coords[0]]))[0]
                     for layer in layers])


def axis_bends(layers: list[Layer], bounds: tuple[float, float] | None = None) -> bool:
    """True when the sections of successive planar layers move as along a bent axis: their
    centroids drift sideways while the section keeps its area and shape, and moving it by
    the drift is what brings it onto the next (a wedge, a flange or a boss moves the centroid
    by growing on one side, which is no bend to follow); and,
    given the thickness `bounds`, a plane can turn at least `MIN_TURN` per layer over the
    sections there without leaving them: a section too wide for that would get 3-D layers
    that all come out parallel, at three OCC cuts each)."""
    if len(layers) < 2:
        return False
    thickness = max(layers[0].thickness, 1e-9)
    window = max(1, int(round(BEND_WINDOW / thickness)))
    n = layers[0].frame.n
    centroids = layer_centroids(layers)
    areas = np.array([layer.area for layer in layers])
    islands = np.array([len(layer.region.geoms) for layer in layers])
    # per window from layer k: the centroids' drift, its lean from n, and whether both ends
    # are one island
    drifts = centroids[window:] - centroids[:-window]
    lengths = np.linalg.norm(drifts, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        leans = np.arccos(np.clip(drifts @ n / lengths, -1.0, 1.0))
    single = (islands[:-window] == 1) & (islands[window:] == 1) & (lengths > 0.0)
    sides = drifts - np.outer(drifts @ n, n)
    for k in range(len(drifts)):
        if not single[k]:
            continue
        ratio = areas[k + window] / areas[k]
        if not 1.0 / BEND_AREA_RATIO <= ratio <= BEND_AREA_RATIO:
            continue
        if not BEND_MIN_ANGLE <= leans[k] <= BEND_MAX_ANGLE:
            continue
        lower, upper = layers[k], layers[k + window]
        moved = _moved_mismatch(lower, upper)
        if moved / max(lower.area, 1e-12) > BEND_SHAPE_CHANGE:
            continue        # the section grew or shrank on one side
        if moved > BEND_MOVE_SHARE * float(lower.region.symmetric_difference(upper.region).area):
            continue        # it moved less than it changed: the drift explains little
        later = [k + j * window for j in range(1, BEND_WINDOWS)]
        if not all(m < len(drifts) and single[m] and leans[m] >= BEND_MIN_ANGLE
                   and _same_side(sides[k], sides[m]) for m in later):
            continue
        if bounds is None:
            return True
        if min(turn_capacity(layers[j], *bounds) for j in (k, k + window)) >= MIN_TURN:
            return True
    return False


def _same_side(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether two sideways drifts point within `BEND_SAME_SIDE_COS` of each other."""
    sizes = float(np.linalg.norm(a) * np.linalg.norm(b))
    return sizes > 0.0 and float(a @ b) / sizes >= BEND_SAME_SIDE_COS


def _moved_mismatch(lower: Layer, upper: Layer) -> float:
    """Area of (lower moved by the centroid drift) △ upper."""
    (x0, y0), (x1, y1) = lower.region.centroid.coords[0], upper.region.centroid.coords[0]
    moved = affinity.translate(lower.region, x1 - x0, y1 - y0)
    return float(moved.symmetric_difference(upper.region).area)


def _shape_change(lower: Layer, upper: Layer) -> float:
    """Area of (lower moved by the centroid drift) △ upper, relative to the lower area."""
    return _moved_mismatch(lower, upper) / max(lower.area, 1e-12)


class _Sections:
    """Sections of one sub-part by planes of any normal (slicers of the last few normals
    kept); `cuts` counts the OCC Booleans."""

    def __init__(self, shape, subpart: int, base: PlanarSlicer | None = None) -> None:
        self.shape = shape
        self.subpart = subpart
        self.cuts = 0
        #: the sub-part's planar slicer, turned for each new normal (its checks reused)
        self._base = base
        self._slicers: OrderedDict[tuple[float, ...], PlanarSlicer] = OrderedDict()
        #: the last section cut (slicer, height, section): where the axis runs straight, a
        #: layer's plane is the very plane its probe was cut on (the fan's hub: 33 of its
        #: 588 sections, ~1.7 ms of B-spline intersections a face)
        self._last: tuple | None = None

    def at(self, point: np.ndarray, normal: np.ndarray) -> PlanarSection:
        _check_finite(self.subpart, point, normal)
        key = tuple(np.round(normal, 12))
        slicer = self._slicers.get(key)
        if slicer is None:
            slicer = self._slicers[key] = (self._base.turned(normal) if self._base is not None
                                           else PlanarSlicer(self.shape, normal))
            while len(self._slicers) > SLICER_CACHE:
                self._slicers.popitem(last=False)
        else:
            self._slicers.move_to_end(key)
        height = float(point @ slicer.frame.n)
        if self._last is not None and self._last[0] is slicer and self._last[1] == height:
            return self._last[2]
        self.cuts += 1
        section = slicer.section(height)
        self._last = (slicer, height, section)
        return section


def section_centroid(section: PlanarSection) -> np.ndarray | None:
    """The area centroid (3D) of a section's polygons, None when it has no finite one."""
    if section.is_empty:
        return None
    region = as_multipolygon(section.polygons())
    if region.is_empty or not region.area > 0:
        return None
    uv = np.array(region.centroid.coords[0], dtype=float)
    point = section.frame.to_3d(uv[None], section.height)[0]
    return point if np.all(np.isfinite(point)) else None


def _points_3d(section: PlanarSection) -> np.ndarray:
    return np.concatenate([section.frame.to_3d(loop.points, section.height) for loop in section.loops])


def slab_thickness(lower: PlanarSection, lower_point: np.ndarray, lower_normal: np.ndarray,
                   upper: PlanarSection, upper_point: np.ndarray,
                   upper_normal: np.ndarray) -> tuple[float, float]:
    """(min, max) distance between the two planes over both sections' boundary points."""
    up = (_points_3d(upper) - lower_point) @ lower_normal
    down = (upper_point - _points_3d(lower)) @ upper_normal
    both = np.concatenate((up, down))
    return float(both.min()), float(both.max())


def _thickness_over(points: np.ndarray, plane_point: np.ndarray, normal: np.ndarray) -> tuple[float, float]:
    """(min, max) distance from `points` up to the plane (`plane_point`, `normal`)."""
    down = (plane_point - points) @ normal
    return float(down.min()), float(down.max())


def tilted_layers(subpart: SubPart, slicer: PlanarSlicer, low: float, high: float,
                  settings: LayerSettings) -> list[Layer]:
    """3-D layers of a sub-part whose centroidal axis bends (see the module docstring)."""
    d_min, d_max = settings.bounds
    nominal = settings.thickness if settings.mode == "uniform" else d_max
    sections = _Sections(subpart.shape, subpart.index, slicer)
    normal = slicer.frame.n
    lower = _first_section(slicer, low, high, nominal)
    plane_point = lower.height * normal
    centroid = section_centroid(lower)
    # Each layer's region is cut on its middle plane, which the chain does not read: those
    # planes go to a second core as they are found (`plane_stream.py`).
    middles = PlaneStream(slicer, int((high - low) / nominal) + 1, settings.workers)
    slabs: list[tuple] = []
    try:
        while centroid is not None:
            step = _next_plane(sections, lower, plane_point, centroid, normal, slicer.frame.n,
                               nominal, d_min, d_max, subpart.index, len(slabs))
            if step is None:
                break
            upper, upper_point, upper_normal, thin, thick, upper_centroid = step
            slab = (plane_point, normal, upper_point, upper_normal, thin, thick)
            middles.submit(*_middle_plane(subpart.index, *slab[:4]))
            slabs.append(slab)
            lower, plane_point, normal, centroid = upper, upper_point, upper_normal, upper_centroid
        regions = middles.results()
    finally:
        middles.close()
    layers = [_layer(section, subpart.index, index, *slab)
              for index, (section, slab) in enumerate(zip(regions, slabs))]
    layers.extend(_planar_top(subpart, sections, plane_point, normal, nominal, d_min, len(layers)))
    if not layers:
        raise PlanError(f"sub-part {subpart.index}: no 3-D layer fits between {d_min:g} and {d_max:g} mm")
    return layers


def _first_section(slicer: PlanarSlicer, low: float, high: float, step: float) -> PlanarSection:
    """The lowest section with a centroid to start the chain from: a part may touch its base
    plane only at a point or an edge, where the section at the base is empty or a sliver
    without a finite centroid (a rod leaning 55° whose rim pokes 0.7 mm below its plate:
    the chain ended before its first layer, and the whole stack came out planar)."""
    height = low + BOUNDARY_INSET
    while height < high:
        section = slicer.section(height)
        if section_centroid(section) is not None:
            return section
        height += step
    raise PlanError(f"no material found along {np.round(slicer.frame.n, 4).tolist()} "
                    f"between {low:.3f} and {high:.3f} mm")


def _next_plane(sections: _Sections, lower: PlanarSection, plane_point: np.ndarray,
                centroid: np.ndarray, normal: np.ndarray, build: np.ndarray, nominal: float,
                d_min: float, d_max: float, subpart: int, index: int):
    """The next plane (section, point, normal, thinnest, thickest, its centroid), or None at
    the top (no material ahead, or no finite centroid there). A normal within
    `PARALLEL_ANGLE` of the build direction `build` snaps to it exactly."""
    thickness = nominal
    worst: tuple[float, float] | None = None
    below = _points_3d(lower)
    while thickness >= d_min - 1e-12:
        probe = sections.at(centroid + thickness * normal, normal)
        ahead = section_centroid(probe)
        if ahead is None:
            return None
        drift = ahead - centroid
        direction = unit(drift, "centroidal axis") if np.linalg.norm(drift) > 1e-12 else normal
        if angle_between(direction, normal) > BEND_MAX_ANGLE:
            direction = normal
        for _ in range(MAX_BISECTIONS):
            if angle_between(direction, build) < PARALLEL_ANGLE:
                direction = build
            point = centroid + thickness * direction
            thin, thick = _thickness_over(below, point, direction)
            if d_min - 1e-9 <= thin and thick <= d_max + 1e-9:
                upper = sections.at(point, direction)
                upper_centroid = section_centroid(upper)
                if upper_centroid is None:
                    return None
                thin, thick = slab_thickness(lower, plane_point, normal, upper, point, direction)
                if d_min - 1e-9 <= thin and thick <= d_max + 1e-9:
                    return upper, point, direction, thin, thick, upper_centroid
            worst = (thin, thick)
            if np.array_equal(direction, normal):
                break
            direction = unit(direction + normal, "bisected axis direction")
            if angle_between(direction, normal) < PARALLEL_ANGLE:
                direction = normal      # the last try is exactly parallel: it fits any Δ in bounds
        thickness -= SHRINK * thickness
    thin, thick = worst if worst is not None else (float("nan"), float("nan"))
    raise PlanError(f"layer {index} of sub-part {subpart} would be {thin:.4f} to {thick:.4f} mm "
                    f"thick at best, outside [{d_min:g}, {d_max:g}] mm: the axis bends too "
                    "sharply for these bounds; widen them or split the sub-part")


def _middle_plane(subpart: int, lower_point: np.ndarray, lower_normal: np.ndarray,
                  upper_point: np.ndarray, upper_normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(point, normal) of the plane bisecting a slab, halfway between its two planes: the
    slab's region is cut there."""
    point = 0.5 * (lower_point + upper_point)
    normal = unit(lower_normal + upper_normal, "middle plane normal")
    _check_finite(subpart, point, normal)
    return point, normal


def _check_finite(subpart: int, point: np.ndarray, normal: np.ndarray) -> None:
    """PlanError naming the sub-part unless the plane (point, normal) is finite."""
    if not (np.all(np.isfinite(point)) and np.all(np.isfinite(normal))):
        raise PlanError(f"sub-part {subpart}: a 3-D layer plane is not finite (point "
                        f"{np.round(point, 4).tolist()}, normal {np.round(normal, 4).tolist()})")


def _layer(section: PlanarSection, subpart: int, index: int, lower_point: np.ndarray,
           lower_normal: np.ndarray, upper_point: np.ndarray, upper_normal: np.ndarray,
           thin: float, thick: float) -> Layer:
    """The slab's layer, its region the `section` on its middle plane."""
    region = as_multipolygon(section.polygons()) if not section.is_empty else MultiPolygon()
    return Layer(subpart=subpart, index=index, frame=section.frame, section_height=section.height,
                 region=region, top_point=upper_point, top_normal=upper_normal,
                 thickness_min=thin, thickness_max=thick)


def _planar_top(subpart: SubPart, sections: _Sections, plane_point: np.ndarray, normal: np.ndarray,
                nominal: float, d_min: float, first_index: int) -> list[Layer]:
    """Parallel layers for what is left above the last tilted plane (thinner than a step)."""
    top = highest_along(subpart.shape, normal)
    base = float(plane_point @ normal)
    remaining = top - base
    if remaining < max(d_min, BOUNDARY_INSET):
        return []
    count = max(1, int(round(remaining / nominal)))
    thickness = remaining / count
    layers = []
    for k in range(count):
        mid = base + (k + 0.5) * thickness
        section = sections.at(mid * normal, normal)
        if section.is_empty:
            continue
        layers.append(Layer(subpart=subpart.index, index=first_index + len(layers), frame=section.frame,
                            section_height=section.height,
                            region=as_multipolygon(section.polygons()),
                            top_point=plane_point + (k + 1) * thickness * normal, top_normal=normal,
                            thickness_min=thickness, thickness_max=thickness))
    return layers
