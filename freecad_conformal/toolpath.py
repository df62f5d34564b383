"""The neutral toolpath: what every planner writes and the post-processor reads (no FreeCAD).

Units: millimetres, mm/min for feeds, seconds for dwells; tool axes are unit vectors.

Model
-----
A `Toolpath` is an ordered list of *segments*; each segment is a polyline of tool poses:
``points`` (n, 3) tool-tip positions in the part frame and ``axes`` (n, 3) unit tool axes
(i, j, k: from the tip back into the tool, so a vertical tool is (0, 0, 1)), with
``segment_index`` (n,) naming the segment of every point (non-decreasing, no empty segment).
Every point is a target reached *from the previous point* as its segment says (so the move
into a segment's first point belongs to that segment); the very first point is reached by a
rapid positioning move. Per segment (arrays of length s):

- ``kind``: index into `KINDS` (travel, deposit, cure, cut);
- ``feed``: tool-tip speed in mm/min;
- ``tool``: tool id (int);
- ``flow``: material per mm (mm³/mm) for deposit, energy per mm (J/mm) for cure, else 0;
- ``interpolation``: index into `INTERPOLATIONS`: "part_linear" (the tip must follow the
  straight line between points within tolerance) or "joint_linear" (the machine joints move
  linearly between points, e.g. a helix on a rotary mandrel; collinear runs become one block).

``events`` are process `Event`s attached before or after a segment: light/laser/extruder
on/off (power as a fraction 0..1), dwell (seconds), tool change (tool id), and for milling
spindle on (rpm)/off and coolant on/off.

Building one::

    builder = ToolpathBuilder(part="cup", material="resin")
    builder.add_segment([[0, 0, 10], [0, 0, 1]], axes=(0, 0, 1), kind="travel", feed=3000)
    builder.event("light_on", power=0.8)            # at the current place in the sequence
    builder.add_segment(ring_xyz, axes=ring_normals, kind="cure", feed=45, tool=1,
                        flow=0.02, interpolation="part_linear")
    builder.event("light_off")
    toolpath = builder.build()                      # validated; raises ToolpathError
    toolpath.save("cup.npz"); Toolpath.load("cup.npz"); toolpath.summary()

Files are ``.npz`` archives of the arrays plus a JSON header (format version, events,
metadata), read without pickle.
"""
from __future__ import annotations

import io
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterable, Sequence

import numpy as np

from freecad_conformal.errors import PostError
from freecad_conformal.fileio import atomic_write
from freecad_conformal.tolerances import AXIS_UNIT_TOLERANCE

KINDS: tuple[str, ...] = ("travel", "deposit", "cure", "cut")
INTERPOLATIONS: tuple[str, ...] = ("part_linear", "joint_linear")
EVENT_ACTIONS: tuple[str, ...] = (
    "light_on", "light_off", "laser_on", "laser_off", "extruder_on", "extruder_off",
    "dwell", "tool_change", "spindle_on", "spindle_off", "coolant_on", "coolant_off",
)
FORMAT_VERSION = 1

#: A tool axis shorter than this is "zero": normalising it would amplify noise into an
#: arbitrary direction.
MIN_AXIS_NORM = 1e-9

#: Default acceleration for the time estimate (mm/s²): a typical value for small
#: multi-axis printers and benchtop mills; machines override it with their own.
DEFAULT_ACCELERATION = 1000.0


class ToolpathError(PostError):
    """The toolpath is malformed (NaN, zero axis, empty, bad segment data) or unreadable."""


@dataclass(frozen=True)
class Event:
    """A process event placed `position` ("before"/"after") segment `segment`."""

    segment: int
    position: str
    action: str
    power: float = 0.0
    seconds: float = 0.0
    tool: int = 0
    rpm: float = 0.0

    def to_json(self) -> dict:
        return {"segment": self.segment, "position": self.position, "action": self.action,
                "power": self.power, "seconds": self.seconds, "tool": self.tool, "rpm": self.rpm}


@dataclass(frozen=True)
class ToolpathSummary:
    """Path length per kind (mm), material (mm³) and energy (J), estimated time (s)."""

    length_by_kind: dict[str, float]
    material_volume: float
    energy: float
    time_s: float
    points: int
    segments: int


@dataclass
class Toolpath:
    points: np.ndarray
    axes: np.ndarray
    segment_index: np.ndarray
    kind: np.ndarray
    feed: np.ndarray
    tool: np.ndarray
    flow: np.ndarray
    interpolation: np.ndarray
    events: tuple[Event, ...] = ()
    metadata: dict[str, str] = field(default_factory=dict)

    @property
    def segment_count(self) -> int:
        return int(len(self.kind))

    @property
    def segment_starts(self) -> np.ndarray:
        """(s + 1,) offsets: segment k holds points[starts[k]:starts[k + 1]]."""
        return np.searchsorted(self.segment_index, np.arange(self.segment_count + 1))

    def kind_name(self, segment: int) -> str:
        return KINDS[int(self.kind[segment])]

    def locate(self, point: int) -> str:
        """'segment S point P' for messages (P counted inside the segment)."""
        seg = int(self.segment_index[point])
        return f"segment {seg} point {point - int(self.segment_starts[seg])} (#{point})"

    def move_lengths(self) -> np.ndarray:
        """(n,) length of the straight move into each point (0 for the first point)."""
        lengths = np.zeros(len(self.points))
        lengths[1:] = np.linalg.norm(np.diff(self.points, axis=0), axis=1)
        return lengths

    def validate(self) -> "Toolpath":
        """Check shapes and values; raise ToolpathError naming the segment and point."""
        validate_toolpath(self)
        return self

    def summary(self, acceleration: float = DEFAULT_ACCELERATION,
                rapid_feed: float | None = None) -> ToolpathSummary:
        """Lengths per kind, material volume (flow × length), energy, and a time estimate.

        Time: each segment is one trapezoidal move of its polyline length at its feed with
        `acceleration` (mm/s²) (corners inside a polyline are not slowed down), travel at
        `rapid_feed` when given, plus dwells.
        """
        per_segment = np.bincount(self.segment_index, weights=self.move_lengths(),
                                  minlength=self.segment_count)
        lengths = {name: float(per_segment[self.kind == code].sum()) for code, name in enumerate(KINDS)}
        deposit = self.kind == KINDS.index("deposit")
        cure = self.kind == KINDS.index("cure")
        feed = self.feed.astype(float).copy()
        if rapid_feed is not None:
            feed[self.kind == KINDS.index("travel")] = rapid_feed
        speed = feed / 60.0
        ramp = speed * speed / acceleration
        time = np.where(per_segment >= ramp, per_segment / speed + speed / acceleration,
                        2.0 * np.sqrt(per_segment / acceleration))
        dwell = sum(e.seconds for e in self.events if e.action == "dwell")
        return ToolpathSummary(
            length_by_kind=lengths,
            material_volume=float((self.flow * per_segment)[deposit].sum()),
            energy=float((self.flow * per_segment)[cure].sum()),
            time_s=float(time.sum() + dwell),
            points=len(self.points), segments=self.segment_count,
        )

    def save(self, path: str | Path) -> None:
        """Write an .npz archive atomically (arrays + JSON header)."""
        data = self.to_bytes()
        with atomic_write(path, "wb") as handle:
            handle.write(data)

    def to_bytes(self) -> bytes:
        """The .npz archive `save` writes, in memory (arrays + JSON header)."""
        validate_toolpath(self)
        header = {"format": "conformal-toolpath", "version": FORMAT_VERSION, "kinds": list(KINDS),
                  "interpolations": list(INTERPOLATIONS), "metadata": self.metadata,
                  "events": [e.to_json() for e in self.events]}
        buffer = io.BytesIO()
        np.savez(buffer, header=np.array(json.dumps(header)), points=self.points,
                 axes=self.axes, segment_index=self.segment_index, kind=self.kind,
                 feed=self.feed, tool=self.tool, flow=self.flow,
                 interpolation=self.interpolation)
        return buffer.getvalue()

    @classmethod
    def load(cls, path: str | Path) -> "Toolpath":
        """Read a file written by `save`; raise ToolpathError if missing or malformed."""
        source = Path(path)
        if not source.is_file():
            raise ToolpathError(f"toolpath file {source} "
                                f"{'is a folder' if source.is_dir() else 'does not exist'}")
        try:
            with np.load(source, allow_pickle=False) as data:
                header = json.loads(str(data["header"]))
                arrays = {name: data[name] for name in ("points", "axes", "segment_index", "kind",
                                                        "feed", "tool", "flow", "interpolation")}
        except (OSError, ValueError, KeyError, EOFError) as exc:   # EOFError: an empty file
            raise ToolpathError(f"toolpath file {source} is not a Conformal toolpath: "
                                f"{exc or type(exc).__name__}") from exc
        if header.get("format") != "conformal-toolpath" or header.get("version") != FORMAT_VERSION:
            raise ToolpathError(f"toolpath file {source}: unsupported header {header.get('format')!r} "
                                f"version {header.get('version')!r}")
        events = tuple(Event(**e) for e in header.get("events", []))
        return cls(events=events, metadata=dict(header.get("metadata", {})), **arrays).validate()


def validate_toolpath(tp: Toolpath) -> None:
    n = len(tp.points)
    if n == 0 or tp.segment_count == 0:
        raise ToolpathError("toolpath is empty: it has no points")
    if tp.points.shape != (n, 3) or tp.axes.shape != (n, 3) or tp.segment_index.shape != (n,):
        raise ToolpathError(f"toolpath arrays disagree: points {tp.points.shape}, axes "
                            f"{tp.axes.shape}, segment_index {tp.segment_index.shape}")
    s = tp.segment_count
    for name in ("feed", "tool", "flow", "interpolation"):
        if getattr(tp, name).shape != (s,):
            raise ToolpathError(f"toolpath per-segment array {name} has shape "
                                f"{getattr(tp, name).shape}, expected ({s},)")
    steps = np.diff(tp.segment_index)
    if tp.segment_index[0] != 0 or np.any((steps != 0) & (steps != 1)) or tp.segment_index[-1] != s - 1:
        raise ToolpathError("toolpath segment_index must run 0, 1, ... without gaps "
                            f"(found first {tp.segment_index[0]}, last {tp.segment_index[-1]}, {s} segments)")
    for name, array in (("coordinate", tp.points), ("tool axis", tp.axes)):
        bad = ~np.isfinite(array).all(axis=1)
        if bad.any():
            i = int(np.argmax(bad))
            raise ToolpathError(f"{name} {array[i].tolist()} is not finite at {tp.locate(i)}")
    norms = np.linalg.norm(tp.axes, axis=1)
    if np.any(norms < MIN_AXIS_NORM):
        i = int(np.argmax(norms < MIN_AXIS_NORM))
        raise ToolpathError(f"tool axis {tp.axes[i].tolist()} is zero at {tp.locate(i)}")
    if np.any(np.abs(norms - 1.0) > AXIS_UNIT_TOLERANCE):
        i = int(np.argmax(np.abs(norms - 1.0)))
        raise ToolpathError(f"tool axis {tp.axes[i].tolist()} is not a unit vector at {tp.locate(i)}")
    _check_segment_values(tp)
    for event in tp.events:
        _check_event(event, s)


def _check_segment_values(tp: Toolpath) -> None:
    checks = (
        ("kind", (tp.kind < 0) | (tp.kind >= len(KINDS)), "an index into KINDS"),
        ("interpolation", (tp.interpolation < 0) | (tp.interpolation >= len(INTERPOLATIONS)),
         "an index into INTERPOLATIONS"),
        ("feed", ~np.isfinite(tp.feed) | (tp.feed <= 0), "a finite speed > 0 mm/min"),
        ("flow", ~np.isfinite(tp.flow) | (tp.flow < 0), "finite and >= 0"),
        ("tool", tp.tool < 0, "a tool id >= 0"),
    )
    for name, bad, wanted in checks:
        if np.any(bad):
            k = int(np.argmax(bad))
            raise ToolpathError(f"segment {k}: {name} {getattr(tp, name)[k]!r} must be {wanted}")


def _check_event(event: Event, segments: int) -> None:
    if event.action not in EVENT_ACTIONS:
        raise ToolpathError(f"unknown event {event.action!r}; known: {', '.join(EVENT_ACTIONS)}")
    if event.position not in ("before", "after") or not 0 <= event.segment < segments:
        raise ToolpathError(f"event {event.action} placed {event.position!r} segment "
                            f"{event.segment}, outside segments 0..{segments - 1}")
    if not (math.isfinite(event.power) and 0.0 <= event.power <= 1.0):
        raise ToolpathError(f"event {event.action}: power {event.power} must be a fraction 0..1")
    if not (math.isfinite(event.seconds) and event.seconds >= 0.0):
        raise ToolpathError(f"event {event.action}: seconds {event.seconds} must be >= 0")
    if not (math.isfinite(event.rpm) and event.rpm >= 0.0):
        raise ToolpathError(f"event {event.action}: rpm {event.rpm} must be >= 0")


class ToolpathBuilder:
    """Accumulates segments and events; `build()` returns a validated `Toolpath`.

    `metadata` keyword arguments (part, material, ...) go into the file header and the
    G-code header comment.
    """

    def __init__(self, **metadata: str) -> None:
        self.metadata = {key: str(value) for key, value in metadata.items()}
        self._points: list[np.ndarray] = []
        self._axes: list[np.ndarray] = []
        self._segments: list[tuple[int, float, int, float, int]] = []
        self._events: list[Event] = []

    def add_segment(self, points: Sequence | np.ndarray, axes: Sequence | np.ndarray = (0, 0, 1), *,
                    kind: str = "deposit", feed: float = 600.0, tool: int = 0, flow: float = 0.0,
                    interpolation: str = "part_linear") -> int:
        """Append a polyline; `axes` is one axis for all points or one per point (normalised).

        Returns the new segment's index. Raises ToolpathError on bad names or shapes.
        """
        segment = len(self._segments)
        xyz = np.array(points, dtype=float).reshape(-1, 3) if np.size(points) else np.empty((0, 3))
        if len(xyz) == 0:
            raise ToolpathError(f"segment {segment} has no points")
        ijk = np.array(axes, dtype=float)
        # One axis for every point (most paths): normalised once, as each row would be.
        one = ijk.shape == (3,)
        ijk = ijk[None] if one else ijk.reshape(-1, 3)
        if not one and ijk.shape != xyz.shape:
            raise ToolpathError(f"segment {segment}: {len(ijk)} tool axes for {len(xyz)} points")
        norms = np.sqrt(np.add.reduce(ijk * ijk, axis=1))     # np.linalg.norm's sum, less its checks
        bad = ~(norms >= MIN_AXIS_NORM)
        if bad.any():
            i = int(np.argmax(bad))
            raise ToolpathError(f"tool axis {ijk[i].tolist()} is zero or not finite at segment "
                                f"{segment} point {i}")
        if kind not in KINDS:
            raise ToolpathError(f"segment {segment}: unknown kind {kind!r}; known: {', '.join(KINDS)}")
        if interpolation not in INTERPOLATIONS:
            raise ToolpathError(f"segment {segment}: unknown interpolation {interpolation!r}; "
                                f"known: {', '.join(INTERPOLATIONS)}")
        self._points.append(xyz)
        unit = ijk / norms[:, None]
        self._axes.append(np.repeat(unit, len(xyz), axis=0) if one else unit)
        self._segments.append((KINDS.index(kind), float(feed), int(tool), float(flow),
                               INTERPOLATIONS.index(interpolation)))
        return segment

    def event(self, action: str, *, power: float = 0.0, seconds: float = 0.0, tool: int = 0,
              rpm: float = 0.0, segment: int | None = None,
              position: str | None = None) -> Event:
        """Attach an event; by default at the current place (after the last segment added)."""
        if segment is None:
            segment = len(self._segments) - 1 if self._segments else 0
            position = position or ("after" if self._segments else "before")
        event = Event(segment, position or "before", action, float(power), float(seconds), int(tool),
                      float(rpm))
        self._events.append(event)
        return event

    def build(self) -> Toolpath:
        if not self._segments:
            raise ToolpathError("toolpath is empty: no segment was added")
        counts = [len(p) for p in self._points]
        columns = list(zip(*self._segments))
        toolpath = Toolpath(
            points=np.concatenate(self._points), axes=np.concatenate(self._axes),
            segment_index=np.repeat(np.arange(len(counts)), counts),
            kind=np.array(columns[0], dtype=np.int8), feed=np.array(columns[1]),
            tool=np.array(columns[2], dtype=np.int64), flow=np.array(columns[3]),
            interpolation=np.array(columns[4], dtype=np.int8),
            events=_ordered(self._events), metadata=dict(self.metadata))
        return toolpath.validate()


def _ordered(events: Iterable[Event]) -> tuple[Event, ...]:
    """Stable order by place in the sequence: (segment, before < after), then insertion."""
    return tuple(sorted(events, key=lambda e: (e.segment, e.position == "after")))
