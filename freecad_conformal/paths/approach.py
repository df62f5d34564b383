"""Safe moves between sub-parts, checked against the material already built.

Leaving a sub-part the tool retracts along its axis until it is outside the *safe sphere*
(the bounding sphere of everything built, plus `SAFE_MARGIN`), travels over that sphere
while the tool axis turns to the next sub-part's direction, and approaches the next first
layer along the new axis. The whole move (tool tip, and the tool body as a line along the
axis) is then measured against the built sub-parts with OCC's exact distance: a move that
comes closer than the tool's envelope allows is a PlanError naming the sub-parts. The
tip must keep half the envelope's tip diameter; the body is the capsule inscribed in the
envelope's cylinder (it misses only the cylinder's base rim).
"""
from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from freecad_conformal.errors import PlanError
from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry.boxes import optimal_box
from freecad_conformal.tolerances import COINCIDENT_POINTS

#: Clearance (mm) between the safe sphere and the built material's bounding sphere: several
#: layer heights and nozzle diameters, so a travel never skims a surface.
SAFE_MARGIN = 5.0

#: Arc points every this many radians over the safe sphere: the chord sag of a 5° step is
#: 0.1 % of the radius, inside the margin for any part that fits a desktop machine.
ARC_STEP = math.radians(5.0)

#: The start of a retract and the end of an approach touch the material by design (the tip
#: leaves or lands on a layer); the check ignores the first and last millimetre along the axis.
CONTACT_LENGTH = 1.0

#: The build plate's normal in the part frame: table-tilting machines reach it at zero
#: angles, so a turn of the tool axis through it never leaves their reach.
UP = np.array([0.0, 0.0, 1.0])

#: Slack (mm) on the clearance checks: OCC distances are exact to far better than this.
CHECK_SLACK = 1e-6

#: A tool axis turning past `UP` closer than this (rad) is turned through it instead. `UP` is
#: where a tilting machine's turntable angle is free (A = 0): an axis passing 0.18° from it
#: needs the turntable to swing 45° and back within a fraction of a degree of tilt, which the
#: post cannot follow within its tolerance (a Y-shaped part's travel between its arms was
#: refused: "the rotary joints jump within it"). Through `UP` the turntable turns while the
#: axis stands there (post/linearize._turn_at_poles). A travel's axis is ours to choose, and
#: 2° off the shortest turn moves the tool body by 3.5 % of its length at most.
POLE_CONE = math.radians(2.0)


def bounding_sphere(shapes: Sequence) -> tuple[np.ndarray, float]:
    """Centre and radius of a sphere holding the bounding boxes of `shapes`."""
    boxes = [shape.BoundBox for shape in shapes]
    low = np.min([[b.XMin, b.YMin, b.ZMin] for b in boxes], axis=0)
    high = np.max([[b.XMax, b.YMax, b.ZMax] for b in boxes], axis=0)
    return 0.5 * (low + high), 0.5 * float(np.linalg.norm(high - low))


def exit_distance(point: np.ndarray, axis: np.ndarray, centre: np.ndarray, radius: float) -> float:
    """Distance along `axis` from `point` to the sphere's surface (0 when already outside)."""
    offset = point - centre
    along = float(offset @ axis)
    gap = along * along - float(offset @ offset) + radius * radius
    return max(0.0, -along + math.sqrt(max(gap, 0.0)))


def slerp_directions(a: np.ndarray, b: np.ndarray, count: int, fallback: np.ndarray) -> np.ndarray:
    """`count` unit vectors from a to b (inclusive) on the great circle; antiparallel a, b
    turn through `fallback`'s component normal to a."""
    a = a / np.linalg.norm(a)
    b = b / np.linalg.norm(b)
    angle = math.acos(float(np.clip(a @ b, -1.0, 1.0)))
    t = np.linspace(0.0, 1.0, count)
    if angle < 1e-9:
        return np.repeat(a[None], count, axis=0)
    if math.pi - angle < 1e-6:
        side = fallback - (fallback @ a) * a
        if np.linalg.norm(side) < COINCIDENT_POINTS:
            side = np.eye(3)[int(np.argmin(np.abs(a)))]
            side = side - (side @ a) * a
        side /= np.linalg.norm(side)
        return np.outer(np.cos(math.pi * t), a) + np.outer(np.sin(math.pi * t), side)
    w = np.sin(np.outer(1.0 - t, [angle])) / math.sin(angle)
    v = np.sin(np.outer(t, [angle])) / math.sin(angle)
    out = w * a + v * b
    return out / np.linalg.norm(out, axis=1)[:, None]


def dips(a: np.ndarray, b: np.ndarray, count: int) -> bool:
    """Whether the shortest turn from a to b dips lower (towards −Z) than either end."""
    return bool(slerp_directions(a, b, count, UP)[:, 2].min() < min(a[2], b[2]) - 1e-9)


def passes_near_up(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether the shortest turn from a to b passes within `POLE_CONE` of `UP` between its
    ends without running through it (3-D layers tilted 0.7° and 0.2° to either side of it
    too).

    In plain floats: asked of every travel, mostly between equal axes, numpy's overhead on
    three-vectors made it 0.17 s of a 2.9 s plan (an enclosure's 3,500 travels)."""
    ax, ay, az = a.tolist() if isinstance(a, np.ndarray) else a
    bx, by, bz = b.tolist() if isinstance(b, np.ndarray) else b
    if ax == bx and ay == by and az == bz:
        return False            # no turn
    la, lb = math.sqrt(ax * ax + ay * ay + az * az), math.sqrt(bx * bx + by * by + bz * bz)
    ax, ay, az, bx, by, bz = ax / la, ay / la, az / la, bx / lb, by / lb, bz / lb
    nx, ny, nz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
    size = math.sqrt(nx * nx + ny * ny + nz * nz)
    if size < 1e-12:
        return False            # no one great circle (parallel ends), or no turn
    nx, ny, nz = nx / size, ny / size, nz / size
    off_circle = abs(nz)        # the normal's component along UP (+Z)
    if off_circle < 1e-12 or off_circle > math.sin(POLE_CONE):
        return False            # through UP exactly, or the circle never comes near
    # The circle's point nearest UP lies on the arc between a and b: both ends on either
    # side of it, seen along the circle.
    px, py, pz = -nz * nx, -nz * ny, 1.0 - nz * nz
    before = (ay * pz - az * py) * nx + (az * px - ax * pz) * ny + (ax * py - ay * px) * nz
    after = (py * bz - pz * by) * nx + (pz * bx - px * bz) * ny + (px * by - py * bx) * nz
    return before > 0 and after > 0


def turn_axis(a: np.ndarray, b: np.ndarray, count: int, over_top: bool | None = None) -> np.ndarray:
    """Tool axes from a to b: the shortest turn, unless it would dip lower (towards −Z) than
    either end, where tilting machines run out of reach, or `over_top` asks for it, or it
    passes close by +Z (`POLE_CONE`); then the turn goes through +Z."""
    through_up = dips(a, b, count) if over_top is None else over_top
    if not (through_up or passes_near_up(a, b)):
        return slerp_directions(a, b, count, UP)
    first = slerp_directions(a, UP, count // 2 + 1, b)
    second = slerp_directions(UP, b, count - count // 2, a)
    return np.vstack((first, second[1:])) if count > 2 else np.vstack((a, b))


def transition(end: np.ndarray, end_axis: np.ndarray, start: np.ndarray, start_axis: np.ndarray,
               centre: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """Points and tool axes from `end` (excluded) to `start` (included) over the safe sphere."""
    safe = radius + SAFE_MARGIN
    lifted = end + exit_distance(end, end_axis, centre, safe) * end_axis
    above = start + exit_distance(start, start_axis, centre, safe) * start_axis
    r1, r2 = np.linalg.norm(lifted - centre), np.linalg.norm(above - centre)
    d1, d2 = (lifted - centre) / r1, (above - centre) / r2
    turn = math.acos(float(np.clip(d1 @ d2, -1.0, 1.0)))
    count = max(2, int(math.ceil(turn / ARC_STEP)) + 1)
    # The tool axis turns the way the tip travels (over the top when the tip does): an axis
    # turning sideways while the tip passes over the top lays the body across the part.
    over_top = dips(d1, d2, count) or dips(end_axis, start_axis, count)
    directions = turn_axis(d1, d2, count, over_top)
    radii = np.linspace(r1, r2, count)
    arc = centre + directions * radii[:, None]
    axes = turn_axis(end_axis, start_axis, count, over_top)
    points = np.vstack((arc, start[None]))
    return points, np.vstack((axes, start_axis[None]))


def check_clearance(points: np.ndarray, axes: np.ndarray, built: Sequence, envelope,
                    what: str, names: str) -> None:
    """Raise PlanError if the move's tip or tool body comes too close to `built` solids.

    `points`/`axes` run from the leaving point (first) to the landing point (last); the
    first and last `CONTACT_LENGTH` mm are where the tip meets the material on purpose.
    """
    if not built or len(points) < 2:
        return
    tip = _trim(points, CONTACT_LENGTH)
    if len(tip) < 2:
        return
    faces = _Faces(built)
    need_tip = 0.5 * envelope.tip_diameter
    tip_gap = faces.gap_below(list(zip(tip[:-1], tip[1:])), need_tip)
    if tip_gap < need_tip - CHECK_SLACK:
        raise PlanError(f"{what}: the tool tip passes {tip_gap:.3f} mm from built {names} "
                        f"(needs {need_tip:.3f} mm)")
    # The body is measured as the capsule inscribed in its cylinder: a segment along the axis
    # from one body radius above the cylinder's base, every point of it needing one radius.
    need_body = 0.5 * envelope.body_diameter
    base = envelope.tip_length + min(need_body, 0.5 * envelope.body_length)
    top = envelope.tip_length + envelope.body_length - min(need_body, 0.5 * envelope.body_length)
    body = [(p + base * a, p + max(top, base + 1e-3) * a) for p, a in zip(points[1:-1], axes[1:-1])]
    if body:
        body_gap = faces.gap_below(body, need_body)
        if body_gap < need_body - CHECK_SLACK:
            raise PlanError(f"{what}: the tool body passes {body_gap:.3f} mm from built {names} "
                            f"(needs {need_body:.3f} mm)")


class _Faces:
    """The faces of the built solids with their boxes, for distance queries from segments.

    One query of a move against the compound of everything built cost OCC ~50 ms (CrankArm:
    0.5 s of its 3.6 s of paths), although nearly all of the move runs far above it. Only
    pairs of a segment and a face whose boxes come within the clearance asked for are
    measured, each exactly: any pair closer than that is among them (a box holds its face,
    OCC's optimal box errs only on the large side), so the verdict is the one a query of
    the whole would give, and so is every gap below the clearance."""

    def __init__(self, built: Sequence) -> None:
        self.faces = [face for solid in built for face in solid.Faces]
        boxes = [optimal_box(face) for face in self.faces]
        self.low = np.array([[b.XMin, b.YMin, b.ZMin] for b in boxes]).reshape(-1, 3)
        self.high = np.array([[b.XMax, b.YMax, b.ZMax] for b in boxes]).reshape(-1, 3)

    def gap_below(self, segments: list[tuple[np.ndarray, np.ndarray]], clearance: float) -> float:
        """The least distance from `segments` (end points) to the faces where it is below
        `clearance` (mm); inf where every segment keeps at least that far from every face."""
        App, Part = import_freecad()
        ends = np.array(segments, dtype=float).reshape(-1, 2, 3)
        low, high = ends.min(axis=1), ends.max(axis=1)
        apart = np.maximum(0.0, np.maximum(low[:, None, :] - self.high[None],
                                           self.low[None] - high[:, None, :]))
        box_gap = np.linalg.norm(apart, axis=2)
        least = np.inf
        for k in np.argsort(box_gap, axis=None):
            i, j = divmod(int(k), len(self.faces))
            if box_gap[i, j] >= min(clearance, least):
                break   # this pair's boxes, and every next pair's, are too far apart
            a, b = ends[i]
            if np.linalg.norm(b - a) <= COINCIDENT_POINTS:
                segment = Part.Vertex(App.Vector(*a))
            else:
                segment = Part.LineSegment(App.Vector(*a), App.Vector(*b)).toShape()
            least = min(least, float(segment.distToShape(self.faces[j])[0]))
        return least


def _trim(points: np.ndarray, length: float) -> np.ndarray:
    """The polyline without its first and last `length` mm."""
    steps = np.linalg.norm(np.diff(points, axis=0), axis=1)
    total = float(steps.sum())
    if total <= 2 * length:
        return points[:0]
    along = np.concatenate(([0.0], np.cumsum(steps)))
    keep = (along > length) & (along < total - length)
    start = np.interp(length, along, np.arange(len(points)))
    end = np.interp(total - length, along, np.arange(len(points)))
    return np.vstack((_at(points, start), points[keep], _at(points, end)))


def _at(points: np.ndarray, position: float) -> np.ndarray:
    k = min(int(position), len(points) - 2)
    return points[k] + (position - k) * (points[k + 1] - points[k])
