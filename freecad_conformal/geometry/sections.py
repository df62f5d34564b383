"""Exact planar sections of B-rep solids (OpenCASCADE through FreeCAD's Part).

Each layer is cut face by face (`face_cut`: plane∩surface curves trimmed to the faces and
filled); layers that are not generic (a vertex or an edge on the plane, a tangency) fall back
to the Boolean common of the solid with a bounded plane. Either way OCC returns faces with
their holes told apart: areas and centroids come from those faces (exact up to OCC's
integration), loops are their wires, and a plane lying on a face of the part returns that
face rather than a ragged set of edges. Polygons for path planning are derived from the
exact wires at a stated chord tolerance.

Heights are signed distances along the (unit) direction from the world origin, so the same
height means the same plane whatever the part's position.
"""
from __future__ import annotations

import copy
from dataclasses import dataclass, field
from typing import Callable, Iterable, Sequence

import numpy as np

from freecad_conformal.errors import GeometryError
from freecad_conformal.geometry.solids import occ_confusion
from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry.boxes import box_reach, optimal_box
from freecad_conformal.geometry.face_sections import FaceCutter
from freecad_conformal.geometry.planar_faces import SectionFace
from freecad_conformal.geometry.prism_runs import copy_sources, free_runs
from freecad_conformal.geometry.analytic_ends import face_top
from freecad_conformal.geometry.plane_curves import STRAIGHT_CURVES, curve_name
from freecad_conformal.geometry.section_pool import cut_sections
from freecad_conformal.geometry.shape_cache import ShapeCache
from freecad_conformal.geometry.shape_parts import faces as faces_of, heights as vertex_heights
from freecad_conformal.geometry.frames import LayerFrame
from freecad_conformal.geometry.loops import Loop, loops_of_faces, polygons_of_loops
from freecad_conformal.geometry.solids import loose_tolerance, solids_of
from freecad_conformal.tolerances import DEFAULT_CHORD_TOLERANCE, MIN_SECTION_AREA, ROUNDING_SLACK

#: The cutting plane extends this far (relative) beyond the solid's bounding box, so no
#: section is clipped by the plane's own border.
PLANE_MARGIN = 0.1

ProgressCallback = Callable[[int, int], None]


@dataclass
class PlanarSection:
    """One layer: the exact section faces of every solid at `height` along the frame normal."""

    height: float
    frame: LayerFrame
    faces: list = field(repr=False)
    chord_tolerance: float = DEFAULT_CHORD_TOLERANCE
    _loops: list[Loop] | None = field(default=None, repr=False)
    #: (area, centroid) once read: the faces' integrals summed, or those of the section this
    #: one is a moved copy of (`_copy_of`: it and the move)
    _measures: tuple | None = field(default=None, repr=False)
    _copy_of: tuple["PlanarSection", np.ndarray] | None = field(default=None, repr=False)
    #: per face, whether its first wire is its outer one (`SectionFace.outer_first`)
    _outer_first: list[bool] | None = field(default=None, repr=False)

    @property
    def area(self) -> float:
        """Exact area (mm²): OCC's integral over the faces, computed when first read (layers
        and paths read the loops, not this)."""
        return self._measured()[0]

    @property
    def centroid(self) -> np.ndarray:
        """Exact area centroid (3,), NaN when empty; computed when first read."""
        return self._measured()[1]

    def _measured(self) -> tuple[float, np.ndarray]:
        if self._measures is None:
            if self._copy_of is not None:
                source, shift = self._copy_of
                self._measures = (source.area, source.centroid + shift)
            else:
                measured = [(item.area, item.centroid)
                            for item in (SectionFace(face) for face in self.faces)]
                area = float(sum(a for a, _ in measured))
                centroid = (sum((c * a for a, c in measured), np.zeros(3)) / area
                            if measured else np.full(3, np.nan))
                self._measures = (area, centroid)
        return self._measures

    @property
    def is_empty(self) -> bool:
        return not self.faces

    @property
    def wires(self) -> list:
        """Exact 3D wires: each face's outer wire followed by its holes."""
        return [wire for face in self.faces for wire in [face.OuterWire] + _holes(face)]

    @property
    def loops(self) -> list[Loop]:
        """Loops in the layer frame (outer counter-clockwise, holes clockwise)."""
        if self._loops is None:
            self._loops = loops_of_faces(self.faces, self.frame, self.chord_tolerance,
                                         outer_first=self._outer_first)
        return self._loops

    def polygons(self):
        """The section as a shapely MultiPolygon in layer coordinates (islands and holes)."""
        return polygons_of_loops(self.loops)

    def to_dict(self, with_points: bool = True) -> dict:
        return {
            "height": self.height,
            "area": self.area,
            "centroid": [float(c) for c in self.centroid],
            "loops": [loop.to_dict(with_points) for loop in self.loops],
        }


@dataclass
class SectionStack:
    """A stack of planar sections along one direction."""

    frame: LayerFrame
    layers: list[PlanarSection]
    chord_tolerance: float
    #: heights whose first cuts came back empty inside the part, and how each was recovered
    repairs: dict[float, str] = field(default_factory=dict)

    @property
    def direction(self) -> np.ndarray:
        return self.frame.n

    def to_dict(self, with_points: bool = True) -> dict:
        """The documented JSON form (docs/sections-format.md)."""
        return {
            "format": "conformal.sections/1",
            "kind": "planar",
            "direction": [float(c) for c in self.frame.n],
            "frame": {"u": [float(c) for c in self.frame.u], "v": [float(c) for c in self.frame.v]},
            "chord_tolerance": self.chord_tolerance,
            "layers": [layer.to_dict(with_points) for layer in self.layers],
            "repaired_layers": [{"height": h, "how": how} for h, how in sorted(self.repairs.items())],
        }

    def wires_compound(self):
        _, Part = import_freecad()
        return Part.Compound([wire for layer in self.layers for wire in layer.wires])


def _holes(face) -> list:
    outer = face.OuterWire
    return [wire for wire in face.Wires if not wire.isSame(outer)]


def uniform_heights(shape, direction: Sequence[float], layer: float) -> list[float]:
    """Mid-layer heights at spacing `layer` covering the shape's extent along `direction`.

    Planes sit at the middle of each layer (first at min + layer/2), the usual slicer choice:
    it never lands on the bottom or top face, and layer area × spacing integrates the volume
    with midpoint-rule accuracy.
    """
    if not np.isfinite(layer) or layer <= 0:
        raise GeometryError(f"layer thickness must be a positive number of mm, got {layer!r}")
    frame = LayerFrame.for_direction(direction)
    low, high = extent_along(shape, frame.n)
    count = int(np.ceil((high - low) / layer - ROUNDING_SLACK))
    if count > 1_000_000:
        raise GeometryError(f"layer {layer} mm gives {count} layers over {high - low:.3f} mm; "
                            "use a thicker layer")
    return [low + (index + 0.5) * layer for index in range(count)]


def extent_along(shape, direction: np.ndarray) -> tuple[float, float]:
    """Exact (min, max) of the shape projected on `direction` (unit).

    Measured as the distance from two far planes (OCC's extrema), whatever the direction:
    bounding boxes are not exact. `optimalBoundingBox` boxes a trimmed B-spline or torus
    face by its whole parameter rectangle (CrankArm's box reaches 1.29 mm below its bottom)
    and `BoundBox` adds tolerances and control polygons (the screw's, 0.83 mm above its top);
    a slicer starting from either lays its first layers in the air.
    """
    return lowest_along(shape, direction), highest_along(shape, direction)


def lowest_along(shape, direction: np.ndarray) -> float:
    """Exact min of the shape projected on `direction` (unit): one end of `extent_along`,
    one distance query (the layout asks only for bottoms)."""
    return _end_along(shape, direction, False)


def highest_along(shape, direction: np.ndarray) -> float:
    """Exact max of the shape projected on `direction` (unit); see `lowest_along`."""
    return _end_along(shape, direction, True)


#: Each shape's exact ends, by shape identity and (direction, which end): the area-jump
#: planes and the layout ask again for a piece they asked of before (Pump_Nut: 5 of 22).
_ENDS: ShapeCache[dict] = ShapeCache(limit=4096, oriented=False)


def _end_along(shape, direction: np.ndarray, high: bool) -> float:
    n = np.asarray(direction, dtype=float)
    return _ENDS.get_keyed((shape,), (tuple(float(c) for c in n), high),
                           lambda: _measured_end(shape, n, high))


def _measured_end(shape, n: np.ndarray, high: bool) -> float:
    """The end along `n` of the faces that may hold it, highest box first, until no box
    reaches past the end found. A planar face bounded by straight edges ends at one of its
    vertices, a plane, cylinder or cone bounded by lines and conics at a closed-form point
    of its edges (`analytic_ends`: within 2.3e-10 mm of OCC's extrema on the 9,108 such
    faces of the shared parts, samples and our own parts in 46 directions, 6x as fast);
    any other face's end is the distance from a far plane to it, one query a face, where
    one query against their compound took OCC several times as long (Pump_Nut's 15 faces
    along Y: 40 ms against 6 ms) for the same number, bit for bit (818 ends of the shared
    parts and samples, 26 to 36 directions each)."""
    App, Part = import_freecad()
    up = n if high else -n
    box = shape.BoundBox
    corners = np.array([[x, y, z] for x in (box.XMin, box.XMax) for y in (box.YMin, box.YMax)
                        for z in (box.ZMin, box.ZMax)])
    reach = float(np.max(np.abs(corners @ n))) + box.DiagonalLength + 1.0
    far = None
    found = -np.inf
    for top, face in _faces_reaching(shape, up) or [(np.inf, shape)]:   # [...]: no face
        if top < found:
            break       # this face's box, and every next one's, ends short of the end found
        vertices = polygon_vertices(face) if face is not shape else None
        if vertices is not None:
            found = max(found, float(np.max(vertices @ up)))
            continue
        closed = face_top(face, up) if face is not shape else None
        if closed is not None:
            found = max(found, closed)
            continue
        if far is None:
            far = _plane_face(Part, App, reach if high else -reach, n,
                              4 * box.DiagonalLength + 2.0, box)
        found = max(found, reach - float(far.distToShape(face)[0]))
    return float(found) if high else float(-found)


#: Planar faces bounded by straight edges only: their vertices, by face identity (None for
#: any other face).
_POLYGONS: ShapeCache = ShapeCache(limit=16384, oriented=False)


def polygon_vertices(face) -> np.ndarray | None:
    """The points of a planar face bounded by straight edges only (its end along any
    direction is one of them), None for any other face."""
    def read():
        if type(face.Surface).__name__ != "Plane" or any(
                curve_name(edge) not in STRAIGHT_CURVES for edge in face.Edges):
            return None
        return np.array([tuple(v.Point) for v in face.Vertexes], dtype=float)
    return _POLYGONS.get((face,), read)




def _faces_reaching(shape, n: np.ndarray) -> list[tuple[float, object]]:
    """(box reach along `n`, face) of the faces that may hold the shape's extreme along
    `n`, highest reach first: a face whose box ends below the highest vertex cannot. The
    box is OCC's optimal one (`boxes.py`), which only errs on the large side."""
    faces = faces_of(shape)
    heights = vertex_heights(shape, n)
    highest = max(heights) if heights else -np.inf
    reaching = [(box_reach(optimal_box(face), n), index) for index, face in enumerate(faces)]
    reaching = sorted((item for item in reaching if item[0] >= highest - BOX_MARGIN),
                      reverse=True)
    return [(top, faces[index]) for top, index in reaching]


def nudged_off(heights: Sequence[float], clear: Callable[[float], bool]) -> list[float]:
    """Each height, or the first of it moved RETRY_NUDGE up, then down, that is `clear`
    (unmoved when none is): `PlanarSlicer.off_vertices`' rule for any cutter."""
    return [next((h for h in (height, height + RETRY_NUDGE, height - RETRY_NUDGE)
                  if clear(h)), height) for height in heights]


#: Slack (mm) on the box test: boxes already enlarge by tolerances, this only guards rounding.
BOX_MARGIN = 1e-6


def _solid_box(App, solid):
    """The solid's box as the union of its faces' optimal boxes: the face cutters and
    `extent_along` box every face anyway (cached, `boxes.py`), where the solid's own optimal
    box boxed them all again (0.04 s a sub-part of the bottle). Planes are only tested
    against it and sized by it, so a box that is not OCC's solid box to the last bit changes
    no section."""
    box = App.BoundBox()
    for face in solid.Faces:
        box.add(optimal_box(face))
    return box


def _plane_face(Part, App, height: float, direction: Sequence[float], size: float, box):
    """A square planar face normal to `direction` at `height`, centred over the box centre."""
    n = np.asarray(direction, dtype=float)
    centre = np.array([box.Center.x, box.Center.y, box.Center.z])
    centre = centre + (height - centre @ n) * n
    frame = LayerFrame.for_direction(n)
    corner = centre - 0.5 * size * (frame.u + frame.v)
    return Part.makePlane(size, size, App.Vector(*corner), App.Vector(*frame.n), App.Vector(*frame.u))


#: An empty section this far (mm) inside a solid's exact extent is a failed cut: closer to the
#: ends it may be a true tangency with nothing to cut.
EXTENT_MARGIN = 1e-6
#: A failed plane is cut again this far (mm) above, then below: off the vertex or tangency
#: that defeated both cuts, and far below any layer height (the error is area × 1e-4 mm).
RETRY_NUDGE = 1e-4
#: A sampling plane crossing a circular edge less than this (mm) inside its extreme is moved
#: too (`FaceCutter.near_circle_extreme`): twice RETRY_NUDGE, so that of the two moves off
#: an extreme only the one to the side where the plane misses the circle is clear.
NEAR_EXTREME = 2 * RETRY_NUDGE
#: Fuzzy value (mm) of the last-resort Boolean: OCC's fuzzy common glues near-coincident
#: geometry within this distance.
FUZZY_VALUE = 1e-5


class PlanarSlicer:
    """Cuts the solids of one shape with planes normal to one direction.

    Building it validates the shape once. Many planes are cut in one Boolean per chunk of
    `CHUNK` heights: OCC's Boolean set-up is then paid once per chunk, not once per layer
    (measured 2× faster on the real parts than one Boolean per layer).
    """

    #: Heights per Boolean; larger chunks lose again as OCC's pave filler grows (measured).
    CHUNK = 32

    def __init__(self, shape, direction: Sequence[float] = (0.0, 0.0, 1.0),
                 chord_tolerance: float = DEFAULT_CHORD_TOLERANCE, *,
                 face_by_face: bool = True) -> None:
        App, Part = import_freecad()
        if not np.isfinite(chord_tolerance) or chord_tolerance <= 0:
            raise GeometryError(f"chord tolerance must be a positive length, got {chord_tolerance!r}")
        self._App, self._Part = App, Part
        self.solids = solids_of(shape)
        self.frame = LayerFrame.for_direction(direction)
        self.chord_tolerance = chord_tolerance
        # Not `BoundBox`: taken from a triangulation it can fall short of a curved face.
        self._boxes = [_solid_box(App, solid) for solid in self.solids]
        self.face_by_face = face_by_face
        self._cutters: dict[int, FaceCutter] = {}
        #: per solid, what its face cutters share whatever the direction (kept by `turned`)
        self._shared: dict[int, dict] = {}
        #: Layers (per solid) cut face by face and by the Boolean fallback, for reports.
        self.counts = {"face_by_face": 0, "boolean": 0}
        #: Heights that came back empty inside a solid and how each was recovered
        #: ("nudged +1e-04 mm", "fuzzy Boolean"): a report says which layers needed what.
        self.repairs: dict[float, str] = {}
        self._extents: dict[int, tuple[float, float]] = {}
        #: heights between which sections are translated copies (`_copy_sources`)
        self._runs: list[tuple[float, float]] | None = None

    def turned(self, direction: Sequence[float]) -> "PlanarSlicer":
        """A slicer of the same solids along another direction, without checking them and
        boxing them again: 3-D layers need one per plane normal, and on a B-spline part
        those checks cost more than the sections (the connecting rod: 84 of 144 s)."""
        other = copy.copy(self)
        other.frame = LayerFrame.for_direction(direction)
        other._cutters = {}
        other._extents = {}
        other.counts = {"face_by_face": 0, "boolean": 0}
        other.repairs = {}
        other._runs = None
        return other

    def section(self, height: float) -> PlanarSection:
        return self.sections([height])[0]

    def sections(self, heights: Sequence[float], progress: ProgressCallback | None = None,
                 workers: int = 1, with_loops: bool = False) -> list[PlanarSection]:
        """Sections at `heights` (any order), in the order given, on `workers` processes.

        Every height is cut face by face first; the layers that path leaves go to the
        Boolean afterwards, up to `CHUNK` of them (per solid) in one Boolean
        (`section_pool.cut_sections`). `with_loops`: the caller reads every section's
        loops, which the processes that cut them then make. Heights in one run of walls
        along the normal (`geometry/prism_runs.py`) are cut once: the others are that
        section moved (the table's legs: 284 of their 285 sections each).
        """
        heights = [float(h) for h in heights]
        # One height has nothing to copy: the 3-D layers' single planes, each along a new
        # normal, skip finding that normal's runs.
        sources = self._copy_sources(heights) if len(heights) > 1 else list(range(len(heights)))
        cut = [index for index, source in enumerate(sources) if source == index]
        layers = cut_sections(self, [heights[index] for index in cut], workers,
                              _in_heights(progress, len(heights)), with_loops)
        made = dict(zip(cut, (self._recover_if_empty(layer) for layer in layers)))
        return [made[index] if source == index else self._moved(made[source], heights[index])
                for index, source in enumerate(sources)]

    def _copy_sources(self, heights: list[float]) -> list[int]:
        """Per height, the one whose section it is a translated copy of (its own if none):
        `prism_runs.copy_sources` over the runs no solid's vertex, face or edge blocks."""
        if not self.face_by_face:
            return list(range(len(heights)))
        if self._runs is None:
            blocked = [span for index in range(len(self.solids))
                       for span in self.cutter(index).blocked_spans()]
            self._runs = free_runs(blocked)
        return copy_sources(self._runs, heights)

    def _moved(self, section: PlanarSection, height: float) -> PlanarSection:
        """`section` moved along the normal to `height`: the same loops in the layer frame."""
        offset = (height - section.height) * self.frame.n
        shift = self._App.Vector(*offset)
        return PlanarSection(height=height, frame=section.frame,
                             faces=[face.translated(shift) for face in section.faces],
                             chord_tolerance=section.chord_tolerance, _loops=section._loops,
                             _copy_of=(section, offset), _outer_first=section._outer_first)

    def off_vertices(self, heights: Sequence[float]) -> list[float]:
        """`heights` moved by RETRY_NUDGE (up, else down) where a vertex of the solids lies
        in the plane, or where it touches a circular edge at its extreme or crosses it just
        inside (NEAR_EXTREME): such a plane costs a Boolean (0.1-0.3 s on a real part)
        where one beside it is cut face by face. For a layer's sampling plane, whose slab
        is a thousand times thicker, the move is immaterial; round-number parts hit it
        often (a feature at 7.5 mm meets the middle of a 0.2 mm layer)."""
        cutters = [self.cutter(index) for index in range(len(self.solids))]
        return nudged_off(heights, lambda height: not any(
            cutter.touches_vertex(height) or cutter.near_circle_extreme(height, NEAR_EXTREME)
            for cutter in cutters))

    def extent(self, solid_index: int) -> tuple[float, float]:
        """Exact (min, max) of one solid along the direction, computed once."""
        if solid_index not in self._extents:
            self._extents[solid_index] = extent_along(self.solids[solid_index], self.frame.n)
        return self._extents[solid_index]

    def _recover_if_empty(self, layer: PlanarSection) -> PlanarSection:
        """A plane strictly inside a solid's extent crosses it (a solid is connected), so an
        empty section there is a failed cut, not a gap: cut again with the plane nudged by
        up to RETRY_NUDGE, then with a fuzzy Boolean; GeometryError when all fail."""
        if not layer.is_empty:
            return layer
        h = layer.height
        crossed = [i for i in range(len(self.solids))
                   if self.extent(i)[0] + EXTENT_MARGIN < h < self.extent(i)[1] - EXTENT_MARGIN]
        if not crossed:
            return layer
        for nudge in (RETRY_NUDGE, -RETRY_NUDGE):
            faces = [f for i in crossed for f in self.cut_boolean(i, np.array([h + nudge]))[0]]
            if faces:
                self.repairs[h] = f"nudged {nudge:+.0e} mm"
                return self.make_section(h, faces)
        faces = [f for i in crossed for f in self._fuzzy_common(i, h)]
        if faces:
            self.repairs[h] = f"fuzzy Boolean ({FUZZY_VALUE:g} mm)"
            return self.make_section(h, faces)
        loose = loose_tolerance(self.solids[crossed[0]])
        why = f"; {loose}: repair the part (Part > Check geometry)" if loose else ""
        raise GeometryError(f"the section at height {h:.6g} mm came back empty although the plane "
                            f"crosses solid {crossed[0] + 1} of {len(self.solids)} (its extent "
                            f"{self.extent(crossed[0])[0]:.6g}..{self.extent(crossed[0])[1]:.6g} mm); "
                            f"face-by-face, Boolean, nudged and fuzzy cuts all failed{why}")

    def _fuzzy_common(self, solid_index: int, height: float) -> list[SectionFace]:
        solid, box = self.solids[solid_index], self._boxes[solid_index]
        size = box.DiagonalLength * (1 + 2 * PLANE_MARGIN) + 1.0
        plane = _plane_face(self._Part, self._App, height, self.frame.n, size, box)
        try:
            common = solid.common([plane], FUZZY_VALUE)
        except Exception:   # OCC's Boolean errors are plain exceptions; the caller reports
            return []
        return [SectionFace(f) for f in common.Faces if f.Area > MIN_SECTION_AREA]

    def _chunks(self, solid_index: int, levels: np.ndarray, size: int | None = None) -> list[np.ndarray]:
        """Indices of `levels` that meet the solid's box, grouped into chunks of `size`."""
        size = size or self.CHUNK
        inside = [i for i, h in enumerate(levels)
                  if _plane_meets_box(self._boxes[solid_index], self.frame.n, h)]
        return [np.array(inside[k:k + size]) for k in range(0, len(inside), size)]

    def cut_faces(self, solid_index: int, heights: np.ndarray) -> list[list[SectionFace] | None]:
        """Section faces of one solid cut face by face (`face_cut`), per height; None where
        that path leaves the layer to the Boolean (a vertex on the plane, a tangency, ...)."""
        if not self.face_by_face:
            result: list = [None] * len(heights)
        else:
            cutter = self.cutter(solid_index)
            result = [cutter.section_faces(float(h)) for h in heights]
        # Face by face, no face encloses MIN_SECTION_AREA or less (planar_faces.MIN_LOOP_AREA).
        return result

    def cutter(self, solid_index: int) -> FaceCutter:
        """The face-by-face cutter of one solid, built on first use."""
        if solid_index not in self._cutters:
            self._cutters[solid_index] = FaceCutter(self.solids[solid_index], self.frame.n,
                                                    self._shared.setdefault(solid_index, {}))
        return self._cutters[solid_index]

    def cut_boolean(self, solid_index: int, heights: np.ndarray) -> list[list[SectionFace]]:
        """Section faces of one solid for each height of a chunk, by one Boolean common."""
        solid, box = self.solids[solid_index], self._boxes[solid_index]
        size = box.DiagonalLength * (1 + 2 * PLANE_MARGIN) + 1.0
        planes = [_plane_face(self._Part, self._App, h, self.frame.n, size, box) for h in heights]
        tool = planes[0] if len(planes) == 1 else self._Part.Compound(planes)
        result = [[] for _ in heights]
        order = np.argsort(heights)
        sorted_heights = heights[order]
        for face in solid.common(tool).Faces:
            if face.Area <= MIN_SECTION_AREA:
                continue
            h = float(np.array(tuple(face.CenterOfMass)) @ self.frame.n)
            slot = int(np.clip(np.searchsorted(sorted_heights, h), 0, len(heights) - 1))
            if slot > 0 and abs(sorted_heights[slot - 1] - h) < abs(sorted_heights[slot] - h):
                slot -= 1
            result[int(order[slot])].append(face)
        return [[SectionFace(face) for face in _merge_touching(faces)] for faces in result]

    def make_section(self, height: float, items: list[SectionFace],
                     loops: list[Loop] | None = None) -> PlanarSection:
        """The section of `items` at `height` (`loops`: its loops, made where it was cut;
        None: discretised when first read)."""
        return PlanarSection(height=float(height), frame=self.frame,
                             faces=[item.face for item in items],
                             chord_tolerance=self.chord_tolerance, _loops=loops,
                             _outer_first=[item.outer_first for item in items])


def _in_heights(progress: ProgressCallback | None, asked: int) -> ProgressCallback | None:
    """`progress` told of the cut sections as a share of the `asked` heights (the copies
    come with the last cut)."""
    if progress is None:
        return None

    def told(done: int, total: int) -> None:
        progress(asked * done // max(total, 1), asked)
    return told


def _merge_touching(faces: list) -> list:
    """One face per island: a plane lying on a face of the part returns that face and the
    section beside it as separate faces sharing edges; fuse and drop the splitter edges."""
    if len(faces) < 2:
        return faces
    boxes = [f.BoundBox for f in faces]
    touching = any(boxes[i].intersect(boxes[j]) for i in range(len(faces))
                   for j in range(i + 1, len(faces)))
    if not touching:
        return faces
    merged = faces[0].fuse(faces[1:]).removeSplitter()
    return [f for f in merged.Faces if f.Area > MIN_SECTION_AREA]


def _plane_meets_box(box, n: np.ndarray, height: float) -> bool:
    corners = np.array([[x, y, z] for x in (box.XMin, box.XMax) for y in (box.YMin, box.YMax)
                        for z in (box.ZMin, box.ZMax)])
    heights = corners @ n
    slack = occ_confusion() * (1.0 + box.DiagonalLength)
    return heights.min() - slack <= height <= heights.max() + slack


def planar_sections(shape, direction: Sequence[float] = (0.0, 0.0, 1.0), *,
                    layer: float | None = None, heights: Iterable[float] | None = None,
                    chord_tolerance: float = DEFAULT_CHORD_TOLERANCE,
                    progress: ProgressCallback | None = None,
                    workers: int = 1) -> SectionStack:
    """Section `shape` with planes normal to `direction`.

    Args:
        shape: a solid or a compound of solids (each is cut separately).
        direction: build direction; need not be unit length.
        layer: uniform spacing (mm); planes at mid-layer heights (see `uniform_heights`).
        heights: explicit heights along the unit direction, instead of `layer`.
        chord_tolerance: largest distance between a loop's polygon and its exact curve (mm).
        progress: called as progress(done, total) as layers complete.
        workers: processes to use (1: this process only); see section_pool.
    Raises:
        GeometryError: bad shape, direction, spacing or heights.
    """
    if (layer is None) == (heights is None):
        raise GeometryError("give exactly one of layer (spacing) or heights")
    slicer = PlanarSlicer(shape, direction, chord_tolerance)
    if heights is None:
        levels = uniform_heights(shape, slicer.frame.n, float(layer))
    else:
        levels = [float(h) for h in heights]
    # Forking costs more than a chunk of layers takes.
    layers = slicer.sections(levels, progress, workers if len(levels) > PlanarSlicer.CHUNK else 1)
    return SectionStack(frame=slicer.frame, layers=layers, chord_tolerance=chord_tolerance,
                        repairs=dict(slicer.repairs))
