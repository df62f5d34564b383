"""Plane sections built face by face: the fast path under `PlanarSlicer`.

A Boolean common pays for a general algorithm (pave filler, face splitting, classification
of every piece) and, on a torus, for OCC's numerical walking. A plane section of a solid
only needs, for each face the plane crosses, the plane∩surface curves trimmed to the face:
analytic from OCC for planes and quadrics (`intersectSS`), closed-form here for tori
(`torus_cut`), OCC's walking for B-spline surfaces. The curves are split where the plane
crosses the face's edges (closed form for lines and circles), kept where they lie inside
the face's parameter domain, chained at those shared crossings into wires and filled.

Anything unusual returns None and the caller falls back to the Boolean: a vertex of the
solid on the plane, an edge in or tangent to it, a crossing that does not join exactly two
curve pieces, a curve ending inside a face, a wire OCC will not close. The fast path only
handles the generic case, where its result is the Boolean's (compared on every real part).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry.boxes import optimal_box
from freecad_conformal.geometry.face_normals import FREEFORM_SURFACES, plane_normal
from freecad_conformal.geometry.frames import cross, points_array
from freecad_conformal.geometry.plane_curves import (ON_CURVE, VERTEX_CLEARANCE, closed_piece, curve_name,
                                                     curve_end, curve_spans, edge_crosser, finite,
                                                     span_middle, surface_curves)
from freecad_conformal.geometry.planar_faces import (Piece, PlaneFrame, SectionFace,
                                                     faces_from_pieces)
from freecad_conformal.geometry.revolved_torus import revolved_torus
from freecad_conformal.geometry.uv_domain import FaceDomain

#: OCC joins two edge ends into one vertex when they are closer than their tolerances
#: (1e-7 mm by default); an analytic piece whose end is further from the crossing point
#: (computed on a walked edge curve, or on an edge stored with a wide tolerance) is closed
#: with a straight bridge to it, or where the gap is too short for an edge (under
#: MIN_BRIDGE), joined by a wider vertex tolerance.
JOIN_TOLERANCE = 5e-8

#: Shortest bridge edge (mm): OCC treats shorter edges as degenerate (Precision::Confusion
#: is 1e-7). A gap left in a wire instead costs its width times its distance from the
#: origin in OCC's boundary integral of the area: gaps of 1e-2 mm on the bottle's neck made
#: a 97.67 mm² section 97.76.
MIN_BRIDGE = 2e-7

#: An edge's 3D curve lies within its tolerance of its faces; a crossing point seen in the
#: plane moves further where the face meets the plane at a slant (bottle along X at 7.1:
#: 0.039 mm off on an edge of tolerance 7.8e-3). This many tolerances first; a crossing on
#: no curve within that is tried at the slant's reach (`FaceCutter._slant_reach`).
EDGE_TOLERANCE_FACTOR = 2.0

#: Below this sine of the angle between plane and face the plane is near tangent there and
#: a crossing's offset from the curve is ill-conditioned: the layer goes to the Boolean.
MIN_SLANT_SINE = 0.02

#: Points at which an open intersection curve crossing no edge is tested against its face.
OPEN_CURVE_SAMPLES = 7


def crossing_reach(edge) -> float:
    """How far (mm) a crossing point on `edge` may lie from the plane∩face curves of its
    faces: ON_CURVE, or EDGE_TOLERANCE_FACTOR times the edge's tolerance where OCC stored
    a wider one (an edge whose 3D curve only approximates its faces: sliced_cylinder's
    elliptic arcs sit up to 3.4e-3 mm off their plane∩cylinder curves, the bottle's thread
    edges 1.2e-2 mm, and no layer of the former along X was cut face by face)."""
    return max(ON_CURVE, EDGE_TOLERANCE_FACTOR * float(edge.Tolerance))


#: OCC integrates area and moments with a fixed number of Gauss points per continuity
#: interval: a fitted cubic B-spline of a hundred knots is one C2 interval, and a nut's
#: section area came out 1.6e-4 off (measured against a dense polygon). Edges of at most
#: this many knot spans integrate within 2e-8 there, and cost little more. Above cubic
#: the points do not keep up even within a few spans (the fan's degree-8 blade curves:
#: 216.35 mm² for a 221.12 mm² section with 16 spans per edge, 221.19 with 4), so each
#: span is its own edge there.
MAX_SPANS_PER_EDGE = 32
MAX_SPANS_ABOVE_CUBIC = 1


def _nearest_parameter(curve, point, reach: float) -> tuple[float, float]:
    """(parameter, distance) of the curve's point nearest `point`. OCC's projection can
    settle on a far local minimum when the point is the curve's end (a trimmed blade's
    curve: 2.3 mm off for a crossing at its end), so the ends are tried when it misses."""
    t = curve.parameter(point)
    gap = float((curve.value(t) - point).Length)
    if gap >= reach:
        for end in (curve.FirstParameter, curve.LastParameter):
            if finite(end):
                end_gap = float((curve.value(end) - point).Length)
                if end_gap < gap:
                    t, gap = end, end_gap
    return t, gap


def _pole_boxes(curves: list) -> list[tuple[np.ndarray, np.ndarray] | None]:
    """Per curve, the box of a B-spline's poles (the curve lies in their hull), None for
    any other curve."""
    boxes = []
    for curve in curves:
        if type(curve).__name__ == "BSplineCurve":
            poles = points_array(curve.getPoles())
            boxes.append((poles.min(axis=0), poles.max(axis=0)))
        else:
            boxes.append(None)
    return boxes


def _match(curves: list, point, reach: float,
           boxes: list | None = None) -> tuple[tuple | None, list[tuple[int, float]]]:
    """The curve nearest `point` within `reach` as (index, parameter, distance), or None;
    and (index, parameter) of every curve within reach that ends there. `boxes`
    (`_pole_boxes`) skip the curves whose box lies beyond reach without projecting on them:
    a thread's flank gives two dozen curves a plane, each crossing asked of each (1.5 s of
    the modelled thread's 5 s of layers)."""
    best = None
    ends = []
    at = np.array([point.x, point.y, point.z])
    for k, curve in enumerate(curves):
        if boxes is not None and boxes[k] is not None:
            low, high = boxes[k]
            if np.linalg.norm(np.maximum(np.maximum(low - at, at - high), 0.0)) >= reach:
                continue
        t, gap = _nearest_parameter(curve, point, reach)
        if gap < reach:
            if best is None or gap < best[2]:
                best = (k, t, gap)
            if curve_end(curve, t):
                ends.append((k, t))
    return best, ends


#: A B-spline face whose (u, v) box covers less than this share of its surface's is
#: intersected with its box's piece of the surface: OCC walks the whole surface otherwise
#: (a decomposition's cut leaves blade stubs of a few per cent of their blade: 5.0 ms a
#: plane for the whole surface, 1.3 ms for the piece).
TRIM_SHARE = 0.8


def _cut_surface(face):
    """The surface a plane is intersected with for `face`: its own; for a B-spline face
    covering little of it, the piece over the face's (u, v) box (the same geometry, cut by
    knot insertion, so the curves are as exact); a circle revolved about an axis in its
    plane as the torus it is (`revolved_torus.py`)."""
    surface = face.Surface
    kind = type(surface).__name__
    if kind == "SurfaceOfRevolution":
        return revolved_torus(surface) or surface
    normal = plane_normal(face) if kind in FREEFORM_SURFACES else None
    if normal is not None:
        # A plane written as a B-spline (a loft's flat side): cut as the plane it is, where
        # OCC's surface intersection walked it (0.39 s a coarse stack across an oblique
        # prism's sides against 0.09 s along its ends).
        App, Part = import_freecad()
        return Part.Plane(face.Vertexes[0].Point, App.Vector(*normal))
    if kind != "BSplineSurface":
        return surface
    u0, u1, v0, v1 = face.ParameterRange
    su0, su1, sv0, sv1 = surface.bounds()
    share = ((u1 - u0) * (v1 - v0)) / max((su1 - su0) * (sv1 - sv0), 1e-300)
    if share >= TRIM_SHARE:
        return surface
    piece = surface.copy()
    try:
        piece.segment(u0, u1, v0, v1)
    except Exception:  # noqa: BLE001 - OCC raises bare Standard_Failure types here
        return surface
    return piece


@dataclass
class _FaceData:
    face: object
    domain: FaceDomain
    low: float
    high: float
    edge_ids: list[int]
    parameter_range: tuple = ()
    #: the surface the plane is intersected with (`_cut_surface`)
    cut_surface: object = None


@dataclass
class _EdgeData:
    edge: object
    #: the cutter's normal: the crosser is made for it on first use (a 3-D layer's cutter
    #: cuts one to three planes, which cross few of the solid's edges)
    normal: np.ndarray
    low: float
    high: float
    faces: list[int]
    #: how far (mm) a crossing on this edge may lie from a face's intersection curve
    reach: float = ON_CURVE
    _crosser: object = None

    @property
    def crosser(self):
        if self._crosser is None:
            self._crosser = edge_crosser(self.edge, self.normal)
        return self._crosser

    @property
    def seam(self) -> bool:
        """An edge of one face only: a seam, whose crossing joins that face to itself."""
        return len(self.faces) == 1


class _Topology:
    """What a cutter reads of its solid whatever the normal: the vertices' points, the
    edges crossed (each once: its edge, hash key, faces and crossing reach) and per face
    its edges' indices and parameter range. Read once per solid (3-D layers make a cutter
    per plane normal: the fan's 276 read it again, 2 ms each)."""

    def __init__(self, solid) -> None:
        self.vertices = [tuple(v.Point) for v in solid.Vertexes]
        self.edges: list[tuple[object, int, list[int], float]] = []
        self.faces: list[tuple[object, list[int], tuple]] = []
        index_of: dict[int, int] = {}
        for face_index, face in enumerate(solid.Faces):
            ids = []
            for edge in face.Edges:
                if edge.Degenerated:
                    continue  # a point in 3D: nothing crosses it
                # Seams stay: OCC may return a curve split where it crosses one, and the
                # crossing there joins its two pieces.
                key = edge.hashCode()
                if key not in index_of:
                    index_of[key] = len(self.edges)
                    self.edges.append((edge, key, [], crossing_reach(edge)))
                faces = self.edges[index_of[key]][2]
                if face_index not in faces:
                    faces.append(face_index)
                if index_of[key] not in ids:
                    ids.append(index_of[key])
            self.faces.append((face, ids, tuple(face.ParameterRange)))


class FaceCutter:
    """Plane sections of one solid, face by face (see the module docstring)."""

    def __init__(self, solid, normal: np.ndarray, shared: dict | None = None) -> None:
        """`shared`: what does not depend on the normal (the solid's topology, faces'
        parameter domains, edges' and faces' boxes), kept across the cutters of one solid
        along many normals (3-D layers cut every plane along its own)."""
        App, Part = import_freecad()
        self._App, self._Part = App, Part
        self.solid = solid
        self.n = np.asarray(normal, dtype=float)
        self._shared = shared if shared is not None else {}
        topology = self._shared.get("topology")
        if topology is None:
            topology = self._shared["topology"] = _Topology(solid)
        self._vertex_heights = np.array([np.dot(point, self.n) for point in topology.vertices])
        self._circle_extremes: tuple[np.ndarray, np.ndarray] | None = None
        self._blocked: list[tuple[float, float]] | None = None
        self.edges: list[_EdgeData] = [
            _EdgeData(edge, self.n, *self._span(edge, ("edge", key)), list(faces), reach)
            for edge, key, faces, reach in topology.edges]
        self.faces: list[_FaceData] = []
        for face_index, (face, ids, parameter_range) in enumerate(topology.faces):
            domain = self._shared.get(("domain", face_index))
            if domain is None:
                domain = self._shared[("domain", face_index)] = FaceDomain(face)
            surface = self._shared.get(("surface", face_index))
            if surface is None:
                surface = self._shared[("surface", face_index)] = _cut_surface(face)
            self.faces.append(_FaceData(face, domain, *self._span(face, ("face", face_index)),
                                        list(ids), parameter_range, surface))

    def prepare(self) -> None:
        """Build every face's parameter domain now (otherwise built on first use)."""
        for data in self.faces:
            data.domain.prepare()

    def _span(self, shape, key) -> tuple[float, float]:
        corners_slack = self._shared.get(("corners", key))
        if corners_slack is None:
            box = optimal_box(shape)  # not `BoundBox`: boxes.py
            corners = np.array([[x, y, z] for x in (box.XMin, box.XMax)
                                for y in (box.YMin, box.YMax) for z in (box.ZMin, box.ZMax)])
            corners_slack = self._shared[("corners", key)] = (
                corners, shape.getTolerance(1) + VERTEX_CLEARANCE)
        corners, slack = corners_slack
        heights = corners @ self.n
        return float(heights.min()) - slack, float(heights.max()) + slack

    def section_faces(self, height: float) -> list[SectionFace] | None:
        """Section faces at `height`, or None when the layer needs the Boolean."""
        if self.touches_vertex(height):
            return None
        points, owners, points_of_face = self._crossings(height)
        if points is None:
            return None
        plane = self._Part.Plane(self._App.Vector(*(height * self.n)), self._App.Vector(*self.n))
        pieces: list[Piece] = []
        for face_index, data in enumerate(self.faces):
            if not data.low < height < data.high:
                continue
            face_pieces = self._face_pieces(data, plane, height, points, owners,
                                            points_of_face[face_index])
            if face_pieces is None:
                return None
            pieces.extend(face_pieces)
        return faces_from_pieces(pieces, len(points), plane)

    def blocked_spans(self) -> list[tuple[float, float]]:
        """Spans along the normal (containing them) of what can change the section: each
        vertex, each face that is not a wall along the normal and each edge that is not a
        line along it (`geometry/prism_runs.py`). Between them sections are translated
        copies."""
        from freecad_conformal.geometry.prism_runs import is_along, is_wall

        if self._blocked is None:
            spans = [(h - VERTEX_CLEARANCE, h + VERTEX_CLEARANCE) for h in self._vertex_heights]
            spans += [(data.low, data.high) for data in self.faces
                      if not is_wall(data.face.Surface, self.n)]
            spans += [(data.low, data.high) for data in self.edges
                      if not is_along(data.edge, self.n)]
            self._blocked = spans
        return self._blocked

    def touches_vertex(self, height: float) -> bool:
        """Whether a vertex of the solid lies in the plane at `height` (not generic)."""
        return bool(np.any(np.abs(self._vertex_heights - height) < VERTEX_CLEARANCE))

    def touches_circle(self, height: float) -> bool:
        """Whether the plane at `height` touches one of the solid's circular edges at its
        extreme along the normal, inside the edge: the crossing there is double, and the cut
        face by face gives up as at a vertex. A guess of which heights the Boolean will cut
        (`section_pool`), never a verdict: the cut itself decides."""
        return self.near_circle_extreme(height, VERTEX_CLEARANCE)

    def near_circle_extreme(self, height: float, reach: float) -> bool:
        """Whether the plane at `height` touches a circular edge at its extreme along the
        normal (`touches_circle`) or crosses it less than `reach` (mm) inside it: two
        crossings δ inside the extreme are 2√(2rδ) apart, and their short chord lies within
        δ of the face's boundary, nearer than the face's domain polygon can place it (off
        by up to 0.016 mm on the bottle's 7.5 mm circles): the cut gives up there too (the
        bottle's circles touched at their lowest points at 27.5 and 28.1 mm, and crossed
        1e-4 mm above them)."""
        tops, bottoms = self._extremes()
        return bool(np.any((tops >= height - VERTEX_CLEARANCE) & (tops < height + reach))
                    or np.any((bottoms <= height + VERTEX_CLEARANCE) & (bottoms > height - reach)))

    def _extremes(self) -> tuple[np.ndarray, np.ndarray]:
        """Heights of the circular edges' highest points and of their lowest points (each
        where it lies on its edge)."""
        if self._circle_extremes is None:
            found = [extreme for data in self.edges if curve_name(data.edge) == "Circle"
                     for extreme in data.crosser.extremes()]
            self._circle_extremes = (np.array([h for h, top in found if top]),
                                     np.array([h for h, top in found if not top]))
        return self._circle_extremes

    def _crossings(self, height: float):
        """Points where the plane crosses the solid's edges, the edge each lies on, and
        their ids per face."""
        points: list[np.ndarray] = []
        owners: list[_EdgeData] = []
        points_of_face: list[list[int]] = [[] for _ in self.faces]
        for data in self.edges:
            if not data.low <= height <= data.high:
                continue
            crossings = data.crosser.at(height)
            if crossings is None:
                return None, None, None
            for point in crossings:
                for face_index in data.faces:
                    points_of_face[face_index].append(len(points))
                points.append(point)
                owners.append(data)
        return points, owners, points_of_face

    def _face_pieces(self, data: _FaceData, plane, height: float, points: list,
                     owners: list[_EdgeData], point_ids: list[int]) -> list[Piece] | None:
        """The face's intersection curves cut at its crossings, the pieces inside it."""
        curves = surface_curves(data.cut_surface, data.parameter_range, plane, self.n, height)
        if curves is None:
            return None
        stops: list[list[tuple[float, int]]] = [[] for _ in curves]
        boxes = _pole_boxes(curves) if len(curves) > 1 and point_ids else None
        for pid in point_ids:
            point = self._App.Vector(*points[pid])
            best, ends = _match(curves, point, owners[pid].reach, boxes)
            if best is None:
                best, _ = _match(curves, point, self._slant_reach(data, point, owners[pid]),
                                 boxes)
            if best is None:
                return None  # a crossing of the face's edges on no curve: not generic
            stops[best[0]].append((best[1], pid))
            # OCC may end two walked curves at the crossing (the fan's hub: 45 of its 1,009
            # sections went to the Boolean for it): the crossing ends each of them, and the
            # piece outside the face is dropped below.
            for k, t in ends:
                if k != best[0]:
                    stops[k].append((t, pid))
        spans = []
        for curve, on_curve in zip(curves, stops):
            for start, end, first, last in curve_spans(curve, sorted(on_curve)):
                if first is None and last is None and not closed_piece(curve, start, end):
                    # An open curve crossing no edge: a torus curve cut to the face's (u, v)
                    # box, wholly outside a face that does not fill its box (the bottle's
                    # side blends along X), or one piece of a walked curve (below).
                    if self._misses_face(data, curve, start, end):
                        continue
                elif not data.domain.contains(span_middle(curve, start, end)):
                    continue
                spans.append([curve, start, end, first, last])
        seam_ids = [pid for pid in point_ids if owners[pid].seam]
        if not self._join_free_ends(spans, points, seam_ids):
            return None
        return [(self._edges(curve, start, end, points, first, last, plane), first, last)
                for curve, start, end, first, last in spans]

    def _slant_reach(self, data: _FaceData, point, owner: _EdgeData) -> float:
        """How far (mm) a crossing on an edge stored with a wide tolerance may lie from the
        face's curve where the face meets the plane at a slant: an edge δ off its face puts
        its crossing δ / sin θ off the curve in the plane, θ the angle between the plane
        and the face (sliced_cylinder's cylinders lean 3.4e-6 rad off their end circles:
        crossings 2.0-15 times the tolerance off, 0.69-0.86 of δ / sin θ; 66 of its layers
        went to the Boolean). EDGE_TOLERANCE_FACTOR of that, and no wider than the edge's
        own reach when the plane is near tangent (MIN_SLANT_SINE). (The bottle's thread
        edges, 1.6e-2 mm off their cylinder, so matched along X at 7.25 give one face of
        111.70 mm² where the Boolean finds three of 111.36: a fine mesh's section is one
        polygon of 111.62.)"""
        if owner.reach <= ON_CURVE:
            return owner.reach
        surface = data.face.Surface
        try:
            u, v = surface.parameter(point)
            normal = np.array(tuple(surface.normal(u, v)))
        except Exception:  # noqa: BLE001 - OCC raises bare Standard_Failure types here
            return owner.reach
        sine = float(np.linalg.norm(cross(normal, self.n)))
        if sine < MIN_SLANT_SINE:
            return owner.reach
        return max(owner.reach, EDGE_TOLERANCE_FACTOR * float(owner.edge.Tolerance) / sine)

    def _join_free_ends(self, spans: list[list], points: list, seam_ids: list[int]) -> bool:
        """Give the spans' free ends inside the face (no crossing there) crossing ids: a
        seam crossing where one lies on it, else one shared with the free end it meets.
        OCC answers a plane ∩ B-spline surface with walked curves that stop at the seam
        and go on from its other side, or meet end to end (the fan's blades: 553 of 1822
        layers went to the Boolean). False when a free end meets neither: a curve ending
        inside the face, not a generic section. New points go at the end of `points`."""
        loose = [(k, side, np.array(tuple(span[0].value(span[1 + side]))))
                 for k, span in enumerate(spans) for side in (0, 1)
                 if span[3 + side] is None and not (span[3] is None and span[4] is None
                                                    and closed_piece(span[0], span[1], span[2]))]
        seams = {pid: points[pid] for pid in seam_ids}
        while loose:
            k, side, point = loose.pop()
            on_seam = [pid for pid, at in seams.items() if np.linalg.norm(at - point) < ON_CURVE]
            if on_seam:
                spans[k][3 + side] = on_seam[0]
                del seams[on_seam[0]]     # a seam crossing joins the two sides once
                continue
            gaps = [float(np.linalg.norm(other - point)) for _, _, other in loose]
            if not gaps or min(gaps) >= ON_CURVE:
                return False
            k2, side2, other = loose.pop(int(np.argmin(gaps)))
            spans[k][3 + side] = spans[k2][3 + side2] = len(points)
            points.append(0.5 * (point + other))
        return True

    @staticmethod
    def _misses_face(data: _FaceData, curve, start: float, end: float) -> bool:
        """Whether the piece from `start` to `end` lies outside the face at all of
        OPEN_CURVE_SAMPLES points (it crosses none of the face's edges, so one verdict
        holds for all of it; several samples guard against a tangent touch)."""
        return not any(data.domain.contains(curve.value(t))
                       for t in np.linspace(start, end, OPEN_CURVE_SAMPLES))

    def _edges(self, curve, start: float, end: float, points: list, first, last, plane) -> list:
        """The piece from `start` to `end` as edges ending on the crossing points.

        A piece across the end of a closed, non-periodic parametrisation becomes two edges.
        B-splines are rebuilt on the plane (`_spline_edges`); an analytic curve cannot move,
        so where it misses a crossing point a straight bridge in the plane joins them.
        """
        Part = self._Part
        spans = [(start, end)]
        lo, hi = curve.FirstParameter, curve.LastParameter
        is_spline = isinstance(curve, Part.BSplineCurve)
        if end > hi + 1e-12 and (is_spline or not curve.isPeriodic()):
            # A span of zero length would make OCC build the whole closed curve.
            spans = [(a, b) for a, b in ((start, hi), (lo, end - (hi - lo))) if b - a > 1e-12]
        if is_spline:
            return self._spline_edges(curve, spans, points, first, last, plane)
        edges = [Part.Edge(curve, a, b) for a, b in spans]
        if first is None:
            return edges
        return self._bridged(edges, curve.value(spans[0][0]), curve.value(spans[-1][1]),
                             points[first], points[last])

    def _bridged(self, edges: list, start, end, first_point, last_point) -> list:
        """`edges` from `start` to `end` joined to the crossing points by bridges where
        they miss them by more than JOIN_TOLERANCE (see MIN_BRIDGE)."""
        Part, Vector = self._Part, self._App.Vector
        head, tail = Vector(*first_point), Vector(*last_point)
        gaps = (float((start - head).Length), float((end - tail).Length))
        narrow = max((g for g in gaps if g <= MIN_BRIDGE), default=0.0)
        if narrow > JOIN_TOLERANCE:
            for edge in edges:
                edge.fixTolerance(2.0 * narrow, Part.Vertex)
        if gaps[0] > MIN_BRIDGE:
            edges = [Part.LineSegment(head, start).toShape(), *edges]
        if gaps[1] > MIN_BRIDGE:
            edges = [*edges, Part.LineSegment(end, tail).toShape()]
        return edges

    def _spline_edges(self, curve, spans: list, points: list, first, last, plane) -> list:
        """B-spline pieces of at most `MAX_SPANS_PER_EDGE` knot spans, ends on the crossings.

        A walked B-spline ends up to ~1e-7 mm off the exact crossing point, more than OCC
        joins edges across: the end poles are set onto the points (a clamped B-spline passes
        through its end poles). The pieces are cut from the curve's image in the plane's
        (u, v) (exact: a B-spline in a plane maps pole by pole), so each edge carries its
        curve on the plane; OCC would otherwise project the 3D curve again for every area
        integral.
        """
        knots = np.array(curve.getKnots())
        most = MAX_SPANS_PER_EDGE if curve.Degree <= 3 else MAX_SPANS_ABOVE_CUBIC
        pieces = []
        for a, b in spans:
            inner = knots[(knots > a + 1e-12) & (knots < b - 1e-12)]
            cuts = [a, *inner[most - 1::most], b]
            if len(cuts) > 2 and cuts[-1] - cuts[-2] < 1e-12:
                cuts.pop(-2)
            pieces.extend(zip(cuts, cuts[1:]))
        Part, Vector2d = self._Part, self._App.Base.Vector2d
        frame = PlaneFrame(plane)
        whole = curve.copy()
        if whole.isPeriodic():
            whole.setNotPeriodic()
        # The image is built once and cut there: segmenting is knot insertion, affine
        # combinations of poles, so it commutes with the map to (u, v) (poles within 3e-14
        # mm of those of pieces cut in 3D and mapped one by one, which took 5.7 s of the
        # pipe elbow's 26 s plan: 16 pieces a loop).
        relative = points_array(whole.getPoles()) - frame.origin
        flat = Part.Geom2d.BSplineCurve2d()
        flat.buildFromPolesMultsKnots(
            [Vector2d(u, v) for u, v in zip((relative @ frame.x_axis).tolist(),
                                            (relative @ frame.y_axis).tolist())],
            whole.getMultiplicities(), whole.getKnots(), False, whole.Degree, whole.getWeights())

        def on_plane(point) -> object:
            u, v = frame.to_2d(np.asarray(point, dtype=float)).tolist()
            return Vector2d(u, v)
        edges = []
        for index, (a, b) in enumerate(pieces):
            piece = flat.copy()
            piece.segment(a, b)
            if index == 0 and first is not None:
                piece.setPole(1, on_plane(points[first]))
            if index == len(pieces) - 1 and last is not None:
                piece.setPole(piece.NbPoles, on_plane(points[last]))
            edges.append(piece.toShape(plane, piece.FirstParameter, piece.LastParameter))
        return edges
