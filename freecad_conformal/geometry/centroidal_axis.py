"""Centroidal axis of a solid on exact sections (METHODS section 3).

Planes step along the search direction P from the base; each section loop's outer boundary
is compared with the loop below it (the upper one projected onto the lower plane, shapely):
    A_upper − (A_upper ∩ A_lower) = A_upper  → the branch broke off and ends;
                                   = ∅        → continuity, the branch goes on;
                                   = ΔA1..ΔAn → a piece whose centre lies much farther from
                                                the lower loop than the step is a turn.
A turn starts a new branch along the nearest of ±X, ±Y, ±Z to C→G, restarting beyond the lower boundary's extreme projection
T on the new direction (S = C + (T − C·P + ε)·P); the region it explains is cut from the
body the father goes on with (B = B − Bs), so every region is searched once. Separate
loops start separate branches (brothers). In "true-direction" mode a branch whose links
drift steadily away from P is re-searched along the drift, so inclined members are
followed in their true direction instead of a staircase of axis turns.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np
from shapely.geometry import Point, Polygon

from freecad_conformal.errors import GeometryError
from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry.axis_graph import AxisGraph
from freecad_conformal.geometry.frames import unit
from freecad_conformal.geometry.sections import PlanarSlicer, extent_along, highest_along
from freecad_conformal.geometry.solids import solids_of

METHODS = ("true-direction", "published")

#: Restart offset after a turn, as in the published method (mm).
RESTART_EPSILON = 1e-3
#: Default number of steps over the part's largest extent along X, Y, Z (or along the start
#: direction, if larger): a part laid flat and searched from +Z is stepped at its length's
#: scale, not its thickness' (CrankArm's arm: 0.6 mm steps along its 150 mm, 13 s).
DEFAULT_STEPS = 40
#: A piece is a turn when its centre is farther than this many steps from the lower loop.
TURN_FACTOR = 2.0
#: Pieces smaller than this fraction of the upper loop are rounding slivers, not turns.
MIN_PIECE_FRACTION = 0.02
#: A link turning more than this from the previous one is a C1 break.
DEFAULT_BREAK_ANGLE = math.radians(45.0)
#: True-direction mode re-searches a branch whose last two links agree within
#: DRIFT_AGREEMENT and both leave P by more than DRIFT_ANGLE.
DRIFT_ANGLE = math.radians(8.0)
DRIFT_AGREEMENT = math.radians(3.0)
#: Runaway guard: more branches than this ends the search with a note.
MAX_BRANCHES = 200

AXES = np.vstack([np.eye(3), -np.eye(3)])


@dataclass
class _Track:
    """An active branch while stepping: its lower loop polygon and centroid."""

    branch: int
    polygon: Polygon
    centroid: np.ndarray
    node: int


def nearest_axis(vector: np.ndarray) -> np.ndarray:
    """The one of ±X, ±Y, ±Z with the smallest angle to `vector`."""
    return AXES[int(np.argmax(AXES @ vector))].copy()


def centroidal_axis(shape, *, method: str = "true-direction", step: float | None = None,
                    start_direction: Sequence[float] = (0.0, 0.0, 1.0),
                    break_angle: float = DEFAULT_BREAK_ANGLE) -> AxisGraph:
    """The centroidal axis graph of `shape` (a solid or compound), searched from its base.

    Raises:
        GeometryError: bad shape, method or step.
    """
    if method not in METHODS:
        raise GeometryError(f"centroidal axis method must be one of {', '.join(METHODS)}, got {method!r}")
    solids = solids_of(shape, "part")
    direction = unit(start_direction, "start direction")
    low, high = extent_along(shape, direction)
    if step is None:
        step = default_step(shape, direction, (low, high))
    if not (math.isfinite(step) and step > 0):
        raise GeometryError(f"centroidal axis step must be a positive length, got {step!r}")
    graph = AxisGraph(method=method, step=float(step))
    search = _Search(graph, method, float(step), break_angle)
    for solid in solids:
        search.explore(solid, direction, low + RESTART_EPSILON, None)
    return graph


def default_step(shape, direction: np.ndarray, extent: tuple[float, float] | None = None) -> float:
    """The axis step when none is given: the shape's largest extent along X, Y, Z or
    `direction` (exact, `extent_along`; `extent` along `direction` when known), over
    DEFAULT_STEPS."""
    direction = np.asarray(direction, dtype=float)
    low, high = extent if extent is not None else extent_along(shape, direction)
    size = high - low
    for axis in AXES[:3]:
        if abs(float(axis @ direction)) < 1 - 1e-12:
            axis_low, axis_high = extent_along(shape, axis)
            size = max(size, axis_high - axis_low)
    return float(size) / DEFAULT_STEPS


class _Search:
    def __init__(self, graph: AxisGraph, method: str, step: float, break_angle: float) -> None:
        self.graph, self.method, self.step, self.break_angle = graph, method, step, break_angle
        self.App, self.Part = import_freecad()
        #: kind of the link that will join the next branch to its father
        self._kind_next = "continue"

    # -- one direction over one body ------------------------------------------------------
    def explore(self, body, P: np.ndarray, start: float, parent_node: int | None,
                parent_branch: int | None = None, same_branch: bool = False) -> None:
        """Step along P from `start` over `body`; `same_branch` continues the father's branch
        (after its turned members were cut away) instead of starting a child branch."""
        if len(self.graph.branches) >= MAX_BRANCHES:
            self.graph.notes.append(f"stopped at {MAX_BRANCHES} branches")
            return
        top = highest_along(body, P)
        heights = list(np.arange(start, top, self.step))
        if not heights:
            return
        try:
            sections = PlanarSlicer(body, P).sections(heights)
        except GeometryError as exc:
            # Only bodies cut out by the search itself get here (the input was checked):
            # a Boolean result OCC's check rejects ends this branch, with a note.
            self.graph.notes.append(f"search along {np.round(P, 3).tolist()} from {start:.3f} "
                                    f"stopped: {exc}")
            return
        tracks: list[_Track] = []
        for index, section in enumerate(sections):
            regions = _regions(section)
            if not tracks:
                tracks = self._first_tracks(regions, P, parent_node, parent_branch,
                                            same_branch, hanging=index > 0)
                continue
            tracks, turns, drift = self._advance(tracks, regions, P)
            for track, piece_centre, lower_polygon in turns:
                body = self._turn(body, P, section.height, track, piece_centre, lower_polygon)
                if body is None:
                    return
            if turns:
                # The father goes on without its turned members: searched again from here.
                last = tracks[0] if tracks else None
                self.explore(body, P, section.height, last.node if last else parent_node,
                             last.branch if last else parent_branch, same_branch=True)
                return
            if drift is not None:
                track, new_direction = drift
                rest = self._beyond(body, P, section.height - self.step)
                if rest is not None:
                    self._bend(rest, track, new_direction)
                    return

    def _first_tracks(self, regions, P, parent_node, parent_branch, same_branch: bool,
                      hanging: bool) -> list[_Track]:
        if same_branch and len(regions) == 1 and parent_branch is not None:
            polygon, centroid, area = regions[0]
            node = self.graph.add_node(centroid, area, parent_branch)
            self._link(parent_node, node, "continue")
            return [_Track(parent_branch, polygon, centroid, node)]
        return [self._start_branch(r, P, parent_node, parent_branch, hanging=hanging)
                for r in regions]

    def _start_branch(self, region, P, parent_node, parent_branch, hanging: bool) -> _Track:
        polygon, centroid, area = region
        branch = self.graph.add_branch(P, parent_branch, hanging=hanging)
        node = self.graph.add_node(centroid, area, branch)
        if parent_node is not None and not hanging:
            self._link(parent_node, node, self._kind_next)
        self._kind_next = "continue"
        return _Track(branch, polygon, centroid, node)

    def _link(self, start: int, end: int, kind: str) -> None:
        """Add a link. Only a turn (a member leaving sideways) can be a break: it is one when
        the child's direction leaves the father's own last link (or its branch direction) by
        more than the break angle. Continue, join and bend links are not: their sideways steps are the
        mixed section where a member leaves, merges, or a branch is re-searched."""
        from freecad_conformal.geometry.axis_graph import AxisLink

        graph = self.graph
        is_break = False
        if kind == "turn":
            # The direction the turn leads into: the child branch's (the link itself only
            # reaches the first centroid of the member, half-way round the corner).
            vector = graph.branches[graph.nodes[end].branch].direction
            branch = graph.nodes[start].branch
            before = [l for l in graph.links
                      if l.end == start and graph.nodes[l.start].branch == branch]
            reference = graph.link_vector(before[-1]) if before else graph.branches[branch].direction
            if np.linalg.norm(vector) > 0 and np.linalg.norm(reference) > 0:
                cos = float(vector @ reference / (np.linalg.norm(vector) * np.linalg.norm(reference)))
                is_break = math.acos(max(-1.0, min(1.0, cos))) > self.break_angle
        graph.links.append(AxisLink(start, end, kind, is_break))

    def _advance(self, tracks: list[_Track], regions: list, P: np.ndarray):
        """Match upper regions to the tracks below; return new tracks, turns and drift."""
        new_tracks: list[_Track] = []
        turns = []
        drift = None
        claimed: dict[int, _Track] = {}
        for track in tracks:
            overlapping = [i for i, r in enumerate(regions) if r[0].intersects(track.polygon)
                           and r[0].intersection(track.polygon).area > 0]
            for i in overlapping:
                polygon, centroid, area = regions[i]
                if i in claimed:
                    # Two branches meet in one loop: this one joins the other.
                    self._link(track.node, claimed[i].node, "join")
                    continue
                if len(overlapping) == 1:
                    branch = track.branch
                else:
                    branch = self.graph.add_branch(P, track.branch)
                node = self.graph.add_node(centroid, area, branch)
                self._link(track.node, node, "continue")
                new = _Track(branch, polygon, centroid, node)
                claimed[i] = new
                new_tracks.append(new)
                for piece in _pieces(polygon.difference(track.polygon), polygon.area):
                    centre = piece.centroid
                    if track.polygon.distance(centre) > TURN_FACTOR * self.step:
                        turns.append((track, _lift(centre, track, P), track.polygon))
                if self.method == "true-direction" and drift is None:
                    drift = self._drift(branch, P)
                    if drift is not None:
                        drift = (new, drift)
        for i, region in enumerate(regions):
            if i not in claimed:
                new_tracks.append(self._start_branch(region, P, None, None, hanging=True))
        return new_tracks, turns, drift

    def _drift(self, branch: int, P: np.ndarray) -> np.ndarray | None:
        nodes = self.graph.branches[branch].nodes
        if len(nodes) < 3:
            return None
        a, b, c = (self.graph.nodes[i].point for i in nodes[-3:])
        first, second = b - a, c - b
        if np.linalg.norm(first) == 0 or np.linalg.norm(second) == 0:
            return None
        first, second = first / np.linalg.norm(first), second / np.linalg.norm(second)
        agree = math.acos(min(1.0, float(first @ second)))
        leave = math.acos(min(1.0, float(second @ P)))
        if agree < DRIFT_AGREEMENT and leave > DRIFT_ANGLE:
            mean = first + second
            return mean / np.linalg.norm(mean)
        return None

    # -- turns and bends --------------------------------------------------------------------
    def _turn(self, body, P, height, track: _Track, centre: np.ndarray, lower: Polygon):
        """Search the turned member as a new branch; return the body the father goes on with."""
        # A turn is a sudden change (a member leaving sideways): both methods take the
        # nearest axis, whose planes square the member; gradual inclination is followed
        # by the drift test instead (true-direction mode).
        new_direction = nearest_axis(centre - track.centroid)
        frame_points = _polygon_points_3d(lower, track, P)
        T = float(np.max(frame_points @ new_direction))
        restart = T + RESTART_EPSILON
        above = self._beyond(body, P, height - self.step)
        if above is None:
            return body
        member = self._beyond(above, new_direction, restart - RESTART_EPSILON)
        if member is None:
            return body
        near = [s for s in member.Solids
                if s.distToShape(self.Part.Vertex(self.App.Vector(*centre)))[0] < 2 * self.step]
        if not near:
            return body
        turned = near[0] if len(near) == 1 else self.Part.Compound(near)
        self._kind_next = "turn"
        self.explore(turned, new_direction, restart, track.node, track.branch)
        rest = body.cut(turned)
        return rest if rest.Solids else None

    def _bend(self, rest, track: _Track, direction: np.ndarray) -> None:
        start = float(track.centroid @ direction)
        self._kind_next = "bend"
        self.explore(rest, direction, start, track.node, track.branch)

    def _beyond(self, body, P: np.ndarray, level: float):
        """The part of `body` on the +P side of the plane at `level` (None if nothing)."""
        from freecad_conformal.geometry.splitting_faces import plane_through

        box = body.BoundBox
        point = P * level
        face = plane_through(point, P, box)
        half = face.extrude(self.App.Vector(*(P * (2 * box.DiagonalLength + 2.0))))
        part = body.common(half)
        return part if part.Solids else None


def _regions(section) -> list[tuple[Polygon, np.ndarray, float]]:
    """(outer-boundary polygon, exact 3D centroid, exact area) per section face."""
    regions = []
    for index, face in enumerate(section.faces):
        outer = [loop for loop in section.loops if loop.outer and loop.face_index == index]
        if not outer or len(outer[0].points) < 3:
            continue
        polygon = Polygon(outer[0].points)
        if not polygon.is_valid:
            polygon = polygon.buffer(0)
        regions.append((polygon, np.array(tuple(face.CenterOfMass)), float(face.Area)))
    return regions


def _pieces(geometry, total: float) -> list[Polygon]:
    parts = getattr(geometry, "geoms", [geometry])
    return [p for p in parts if isinstance(p, Polygon) and not p.is_empty
            and p.area > MIN_PIECE_FRACTION * total]


def _lift(centre: Point, track: _Track, P: np.ndarray) -> np.ndarray:
    """A 2D piece centre back in 3D, on the lower section's plane."""
    from freecad_conformal.geometry.frames import LayerFrame

    frame = LayerFrame.for_direction(P)
    return frame.to_3d(np.array([[centre.x, centre.y]]), float(track.centroid @ frame.n))[0]


def _polygon_points_3d(polygon: Polygon, track: _Track, P: np.ndarray) -> np.ndarray:
    from freecad_conformal.geometry.frames import LayerFrame

    frame = LayerFrame.for_direction(P)
    return frame.to_3d(np.asarray(polygon.exterior.coords), float(track.centroid @ frame.n))
