"""Pencil passes: a tapered cutter (a V-bit) run along the sharp concave edges of a part,
where a flat end mill leaves stock (within r·cot(opening / 2) of the edge, 7.24 mm for a
6 mm cutter in a 45° wedge; `geometry/stock.corner_zones`).

The edge must be straight and its two faces planar, and the V-bit's cone narrower than the
wedge. In the plane across the edge the cutter is a polygon (its tip flat, the cone to the
shank's diameter, the shank, the holder); each pass lays the cone's flank along one face,
its tip in the corner (pushed out along that face only as far as the tip flat needs to
stay off the other face), and moves the cutter along the edge from beyond one end of the
part to beyond the other, so it enters and leaves through air whatever the faces around.
The flank then cuts its face exactly out to the cone's end; the pass on the other face
takes the rest of the wedge, and what stays is a speck at the tip flat (a 0.05 mm flat in
a 45° wedge leaves under 0.03 mm).

The volume a pass sweeps is the cutter's polygon drawn along the edge: a `Prism` in a frame
whose normal is the edge, exactly what the material check subtracts. A pass is kept only
if neither its flutes nor its shank and holder reach into the part at any sampled surface
point (moved `GOUGE_PROBE` inside).
"""
from __future__ import annotations

import math
from typing import Sequence

import numpy as np
from shapely.geometry import Polygon

from freecad_conformal.geometry.frames import LayerFrame
from freecad_conformal.geometry.stock import Prism
from freecad_conformal.paths.milling import MillPass, MillTool

#: A wedge must open wider than the cone by this (rad) for a pass: the far flank then
#: clears the other face by at least half of it.
TAPER_CLEARANCE = math.radians(1.0)

#: Sampled surface points are moved this far (mm) into the part before asking whether a
#: pass reaches them: the flank lies on its face, and points on it must not count.
GOUGE_PROBE = 0.005

#: A pass starts and ends this far (mm) beyond the part along the edge, past the holder.
END_CLEARANCE = 2.0

#: A pass cuts at its feed from this far (mm) before its flutes reach the edge's end to as
#: far past the other: stock lies along the edge only.
LEAD_MARGIN = 1.0


def cutter_outline(tool: MillTool) -> tuple[np.ndarray, np.ndarray]:
    """(flutes, body): the tapered cutter across its axis as (r, h) polygons, the tip's
    centre at the origin and h up the axis; the body is the shank above the flutes and
    the holder."""
    half = math.radians(0.5 * tool.taper_deg)
    tip = 0.5 * tool.tip_diameter
    cone = (tool.radius - tip) / math.tan(half)
    top = tool.flute_length
    flutes = np.array([(-tip, 0.0), (tip, 0.0), (tool.radius, cone), (tool.radius, top),
                       (-tool.radius, top), (-tool.radius, cone)])
    holder, grip = 0.5 * tool.holder_diameter, tool.stick_out
    body = np.array([(-tool.radius, top), (tool.radius, top), (tool.radius, grip),
                     (holder, grip), (holder, grip + tool.holder_length),
                     (-holder, grip + tool.holder_length), (-holder, grip),
                     (-tool.radius, grip)])
    return flutes, body


def flank_pose(opening: float, tool: MillTool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(origin, axis, across) of the cutter in a wedge's plane: the corner at (0, 0), one
    face along +x, the other at `opening` (rad) towards +y. The cone's flank lies on the
    +x face; `origin` is the tip's centre, `axis` points up the cutter, `across` is its +r."""
    half = math.radians(0.5 * tool.taper_deg)
    axis = np.array([math.cos(half), math.sin(half)])
    across = np.array([-math.sin(half), math.cos(half)])
    # the flank r = -(tip + h·tan) lies on y = 0 when the tip's centre stands tip·cos above it
    origin = np.array([0.0, 0.5 * tool.tip_diameter * math.cos(half)])
    # where the tip flat crosses the other face's line, slide along +x until it does not
    depth = _crossing(origin, axis, across, _inward(opening)[1], tool)
    return origin + np.array([depth / math.sin(opening), 0.0]), axis, across


def wedge_poses(opening: float, tool: MillTool) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Poses (`flank_pose`'s) that sweep the whole wedge near its corner: the flank on
    each face, and between them cones whose axes fan out at most `FAN_SPACING` of the
    cone's angle apart, each tip pushed out along its axis just clear of both faces."""
    taper = math.radians(tool.taper_deg)
    first = flank_pose(opening, tool)
    mirror = np.array([[math.cos(opening), math.sin(opening)],
                       [math.sin(opening), -math.cos(opening)]])   # across the bisector
    last = tuple(mirror @ v for v in first)
    count = 1 + math.ceil((opening - taper) / (FAN_SPACING * taper) - 1e-9)
    poses = [first]
    for k in range(1, count - 1):
        angle = 0.5 * taper + k * (opening - taper) / (count - 1)
        axis = np.array([math.cos(angle), math.sin(angle)])
        across = np.array([-math.sin(angle), math.cos(angle)])
        push = max(_crossing(np.zeros(2), axis, across, inward, tool) / float(axis @ inward)
                   for inward in _inward(opening))
        poses.append((push * axis, axis, across))
    return poses + [last]


#: Cones between the two flank passes fan out at most this fraction of the cone's angle
#: apart: neighbours overlap, so no sliver between them stays uncut.
FAN_SPACING = 0.75


def _inward(opening: float) -> tuple[np.ndarray, np.ndarray]:
    """Unit normals of the wedge's two face lines, pointing into the wedge."""
    return np.array([0.0, 1.0]), np.array([math.sin(opening), -math.cos(opening)])


def _crossing(origin: np.ndarray, axis: np.ndarray, across: np.ndarray, inward: np.ndarray,
              tool: MillTool) -> float:
    """How far (mm) the cone placed so reaches past a face line (0 when it does not)."""
    flutes, _ = cutter_outline(tool)
    cone = outline_at(flutes[[0, 1, 2, 5]], origin, axis, across)
    return max(0.0, -float((cone @ inward).min()))


def outline_at(outline: np.ndarray, origin: np.ndarray, axis: np.ndarray,
               across: np.ndarray) -> np.ndarray:
    """An (r, h) outline placed with its tip's centre at `origin`."""
    return origin + outline[:, :1] * across + outline[:, 1:] * axis


def pencil_passes(part, tools: Sequence[MillTool], points: np.ndarray, normals: np.ndarray,
                  notes: list[str]) -> list[MillPass]:
    """Passes of the tapered `tools` along the sharp straight concave edges of `part`
    (`points`, `normals`: samples of its surface, `geometry/stock.surface_samples`)."""
    from freecad_conformal.geometry.concave_edges import concave_edges

    tapered = sorted((t for t in tools if t.tapered), key=lambda t: -t.taper_deg)
    if not tapered:
        return []
    probes = points - GOUGE_PROBE * normals
    box = np.array([[x, y, z] for x in (part.BoundBox.XMin, part.BoundBox.XMax)
                    for y in (part.BoundBox.YMin, part.BoundBox.YMax)
                    for z in (part.BoundBox.ZMin, part.BoundBox.ZMax)])
    passes: list[MillPass] = []
    skipped = 0
    for found in concave_edges(part):
        corner = _wedge(part, found)
        if corner is None:
            continue
        point, face_a, face_b, opening, ends = corner
        tool = next((t for t in tapered
                     if math.radians(t.taper_deg) + TAPER_CLEARANCE < opening), None)
        if tool is None:
            skipped += 1
            continue
        for pose in wedge_poses(opening, tool):
            made = _pass(tool, point, face_a, face_b, pose, box, probes, ends)
            if made is None:
                skipped += 1
            else:
                passes.append(made)
    if skipped:
        notes.append(f"{skipped} corner pencil pass(es) left out: the V-bit would not fit "
                     "the wedge or would reach into the part")
    return passes


def _wedge(part, found) -> tuple | None:
    """(a point on the edge, unit directions leaving it into each face, the opening, the
    edge's two ends)
    of a straight concave edge between two planes; None for any other edge."""
    from freecad_conformal.geometry.concave_edges import into_face

    edge = found.edge
    faces = [part.Faces[i] for i in found.faces]
    if type(edge.Curve).__name__ not in ("Line", "LineSegment"):
        return None
    if any(type(f.Surface).__name__ != "Plane" for f in faces):
        return None
    start = np.array(tuple(edge.valueAt(edge.FirstParameter)))
    end = np.array(tuple(edge.valueAt(edge.LastParameter)))
    direction = (end - start) / np.linalg.norm(end - start)
    middle = 0.5 * (start + end)
    into = []
    for face in faces:
        u0, u1, v0, v1 = face.ParameterRange
        normal = np.array(tuple(face.normalAt(0.5 * (u0 + u1), 0.5 * (v0 + v1))))
        into.append(into_face(face, middle, direction, normal, 1e-3 * edge.Length))
    opening = math.acos(float(np.clip(into[0] @ into[1], -1.0, 1.0)))
    if not 0.0 < opening < math.pi:
        return None
    return middle, into[0], into[1], opening, np.array([start, end])


def _pass(tool: MillTool, point: np.ndarray, along: np.ndarray, other: np.ndarray,
          pose: tuple, box: np.ndarray, probes: np.ndarray, ends: np.ndarray) -> MillPass | None:
    """The pass at `pose` in the wedge whose faces leave the edge `point` lies on along
    `along` and `other`, or None if it would reach into the part. It cuts at its feed
    where its flutes meet the edge (`ends`) and moves at travel speed through the air
    before and after."""
    side = other - float(other @ along) * along
    side /= np.linalg.norm(side)
    normal = np.cross(along, side)                 # right-handed: along × side = normal
    frame = LayerFrame(u=along, v=side, n=normal)
    corner = frame.to_2d(point[None])[0]
    origin, axis, across = pose
    flutes, body = cutter_outline(tool)
    region = Polygon(corner + outline_at(flutes, origin, axis, across))
    heights = box @ normal
    reach = 0.5 * tool.holder_diameter + END_CLEARANCE
    low, high = float(heights.min()) - reach, float(heights.max()) + reach
    sweep = Prism(frame, region, low, high - low)
    shank = Prism(frame, Polygon(corner + outline_at(body, origin, axis, across)), low, high - low)
    if sweep.holds(probes).any() or shank.holds(probes).any():
        return None
    tip = frame.to_3d((corner + origin)[None], 0.0)[0]
    spans = sorted(float(e @ normal) for e in ends)
    cut_low = max(low, spans[0] - tool.radius - LEAD_MARGIN)
    cut_high = min(high, spans[1] + tool.radius + LEAD_MARGIN)
    heights = [low, cut_low, cut_high, high] if low < cut_low < cut_high < high else [low, high]
    tool_axis = axis[0] * along + axis[1] * side
    return MillPass(np.array([tip + h * normal for h in heights]),
                    tool_axis / np.linalg.norm(tool_axis), "pencil", tool, tool.feed, sweep,
                    lead=1 if len(heights) == 4 else 0)
