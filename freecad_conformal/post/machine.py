"""Machines as data: `resources/machines/<name>.json`, checked against a schema on load.

Conventions (see docs/post.md):
- Linear axes X, Y, Z are commanded as the tool tip relative to the part zero, whichever side
  physically moves (`moves` records it for people and simulators).
- The part frame equals the machine frame with every rotary axis at 0.
- Rotary axes: `on` "table" (rotates the part) or "head" (rotates the tool), `direction` (unit
  vector at zero angles, right-hand positive rotation) and `pivot` (a point on the axis: part
  frame for table axes, relative to the tool tip at zero angles for head axes). Within each
  side, list axes from the machine base outward (the first carries the second).
- `continuous`: no limits (unwound, never jumps 360°); `wrap`: the controller wants angles in
  [0, 360) and takes the short way (only for continuous axes).
"""
from __future__ import annotations

import dataclasses
import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from freecad_conformal.errors import KinematicsError
from freecad_conformal.tolerances import ZERO_LENGTH

MACHINES_DIR = Path(__file__).resolve().parents[2] / "resources" / "machines"
LINEAR_NAMES = ("X", "Y", "Z")
ROTARY_NAMES = ("A", "B", "C")
#: How the program switches a light or laser: the spindle output (M3 S), a fan output
#: (Marlin M106) or analog output 0 (LinuxCNC M68 E0 Q, the usual laser power input of a
#: hybrid machine whose spindle drives the mill)
LIGHT_CONTROLS = ("spindle", "fan", "analog")
#: Seconds a switch between deposition and milling takes when the machine file does not
#: say (METHODS section 6: about 30 s: head change, purge, spindle run-up)
DEFAULT_PROCESS_SWITCH_S = 30.0

_TOP_KEYS = {"name": str, "dialect": str, "linear_axes": dict, "rotary_axes": list,
             "tool_direction": list, "home": dict, "rapid_feed": (int, float),
             "max_feed": (int, float), "max_rotary_feed": (int, float),
             "acceleration": (int, float), "light_control": str, "spindle_max": (int, float),
             "filament_diameter": (int, float), "description": str, "start_gcode": list,
             "end_gcode": list, "temperatures": dict, "home_on_start": bool,
             "tool_change_z": (int, float), "tool_lengths": dict,
             "process_switch_s": (int, float), "platform": bool}
_OPTIONAL_TOP = {"description", "light_control", "spindle_max", "filament_diameter",
                 "start_gcode", "end_gcode", "temperatures", "home_on_start", "tool_change_z",
                 "tool_lengths", "process_switch_s", "platform"}
_HEATERS = ("hotend", "bed")
_ROTARY_KEYS = {"name": str, "on": str, "direction": list, "pivot": list, "limits": list,
                "continuous": bool, "wrap": bool}


@dataclass(frozen=True)
class LinearAxis:
    name: str
    limits: tuple[float, float]
    moves: str


@dataclass(frozen=True)
class RotaryAxis:
    name: str
    on: str
    direction: np.ndarray
    pivot: np.ndarray
    limits: tuple[float, float] | None   # radians; None when continuous
    continuous: bool
    wrap: bool


@dataclass(frozen=True)
class Machine:
    """A checked machine definition (angles in radians inside)."""

    name: str
    source: str
    dialect: str
    linear: tuple[LinearAxis, ...]
    rotary: tuple[RotaryAxis, ...]
    tool_direction: np.ndarray
    home: dict[str, float]
    rapid_feed: float
    max_feed: float
    max_rotary_feed: float   # degrees per minute
    acceleration: float      # mm/s²
    light_control: str
    spindle_max: float
    filament_diameter: float
    start_gcode: tuple[str, ...] = ()    # lines after the dialect's preamble
    end_gcode: tuple[str, ...] = ()      # lines before the dialect's postamble
    temperatures: tuple[tuple[str, float], ...] = ()   # (heater, °C): waited for at the start
    home_on_start: bool = False          # home (G28) before the first move (Marlin family)
    tool_change_z: float | None = None   # machine-coordinate Z (G53) for tool changes
    #: (tool, mm): how much longer each tool is than the one the head pivots are measured
    #: from; head machines need it for every tool they use when they use more than one
    tool_lengths: tuple[tuple[int, float], ...] = ()
    #: seconds a switch between deposition and milling takes (hybrid plans)
    process_switch_s: float = DEFAULT_PROCESS_SWITCH_S
    #: False: nothing flat to build on at Z = 0 (a rotary mandrel, whose part grows on a
    #: spinning cylinder); platform plans are refused, mandrel builds are what it makes
    platform: bool = True

    def for_tool(self, tool: int) -> "Machine":
        """This machine with its head pivots measured from the tip of `tool`.

        A tool `length` mm longer puts its tip that much farther along the tool direction
        from every head pivot. Table-only machines are returned as they are: there the
        controller applies the tool length (G43 H). Raises KinematicsError for a head
        machine with tool lengths that does not list `tool`.
        """
        if not self.head_axes or not self.tool_lengths:
            return self
        lengths = dict(self.tool_lengths)
        if tool not in lengths:
            raise KinematicsError(f"machine {self.name} has head rotary axes and tool_lengths "
                                  f"for tools {sorted(lengths)}, but not for tool {tool}")
        shift = lengths[tool] * self.tool_direction
        rotary = tuple(dataclasses.replace(a, pivot=a.pivot + shift) if a.on == "head" else a
                       for a in self.rotary)
        return dataclasses.replace(self, rotary=rotary, tool_lengths=())

    @property
    def joint_names(self) -> tuple[str, ...]:
        return LINEAR_NAMES + tuple(axis.name for axis in self.rotary)

    @property
    def table_axes(self) -> tuple[RotaryAxis, ...]:
        return tuple(a for a in self.rotary if a.on == "table")

    @property
    def head_axes(self) -> tuple[RotaryAxis, ...]:
        return tuple(a for a in self.rotary if a.on == "head")

    def home_joints(self) -> np.ndarray:
        """Joint vector at home: X, Y, Z in mm, then rotary axes in radians."""
        values = [self.home.get(n, 0.0) for n in LINEAR_NAMES]
        values += [math.radians(self.home.get(a.name, 0.0)) for a in self.rotary]
        return np.array(values, dtype=float)


def machine_names() -> list[str]:
    """Stems of the shipped machine files."""
    return sorted(p.stem for p in MACHINES_DIR.glob("*.json"))


def load_machine(name_or_path: str | Path) -> Machine:
    """Load a shipped machine by file stem, or any machine JSON by path.

    Raises KinematicsError for an unknown name, a missing file or a schema violation.
    """
    candidate = Path(name_or_path)
    if candidate.suffix == ".json" or candidate.exists():
        path = candidate
    else:
        path = MACHINES_DIR / f"{name_or_path}.json"
        if not path.is_file():
            raise KinematicsError(f"unknown machine {str(name_or_path)!r}; shipped machines: "
                                  f"{', '.join(machine_names())} (or give a path to a .json file)")
    if not path.is_file():
        raise KinematicsError(f"machine file {path} "
                              f"{'is a folder' if path.is_dir() else 'does not exist'}")
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise KinematicsError(f"machine file {path} is not valid JSON: {exc}") from exc
    return machine_from_dict(data, source=str(path))


def machine_from_dict(data: dict, source: str = "<dict>") -> Machine:
    """Check `data` against the schema and build a Machine; errors name file and key."""
    where = f"machine {source}"
    if not isinstance(data, dict):
        raise KinematicsError(f"{where}: top level must be an object")
    _check_keys(data, _TOP_KEYS, set(_TOP_KEYS) - _OPTIONAL_TOP, where)
    linear = tuple(_linear_axis(data["linear_axes"], name, where) for name in LINEAR_NAMES)
    if set(data["linear_axes"]) - set(LINEAR_NAMES):
        raise KinematicsError(f"{where}: linear_axes may only name X, Y, Z, "
                              f"found {sorted(data['linear_axes'])}")
    rotary = tuple(_rotary_axis(entry, i, where) for i, entry in enumerate(data["rotary_axes"]))
    names = [a.name for a in rotary]
    if len(set(names)) != len(names) or len(rotary) > 2:
        raise KinematicsError(f"{where}: rotary_axes must be at most two distinct axes, got {names}")
    home = data["home"]
    for key, value in home.items():
        if key not in LINEAR_NAMES + tuple(names) or not _is_number(value):
            raise KinematicsError(f"{where}: home.{key} = {value!r} is not a number for an axis "
                                  f"of this machine")
    light = data.get("light_control", "spindle")
    if light not in LIGHT_CONTROLS:
        raise KinematicsError(f"{where}: light_control {light!r} must be one of {LIGHT_CONTROLS}")
    if light == "analog" and data["dialect"] != "linuxcnc":
        raise KinematicsError(f"{where}: light_control 'analog' (M68) needs dialect linuxcnc, "
                              f"not {data['dialect']!r}")
    for key in ("rapid_feed", "max_feed", "max_rotary_feed", "acceleration", "spindle_max",
                "filament_diameter", "process_switch_s"):
        if key in data and not (_is_number(data[key]) and data[key] > 0):
            raise KinematicsError(f"{where}: {key} = {data[key]!r} must be > 0")
    return Machine(
        name=data["name"], source=source, dialect=data["dialect"], linear=linear, rotary=rotary,
        tool_direction=_unit(data["tool_direction"], f"{where}: tool_direction"),
        home={k: float(v) for k, v in home.items()}, rapid_feed=float(data["rapid_feed"]),
        max_feed=float(data["max_feed"]), max_rotary_feed=float(data["max_rotary_feed"]),
        acceleration=float(data["acceleration"]), light_control=light,
        spindle_max=float(data.get("spindle_max", 1000.0)),
        filament_diameter=float(data.get("filament_diameter", 1.75)),
        start_gcode=_gcode_lines(data.get("start_gcode", []), f"{where}: start_gcode"),
        end_gcode=_gcode_lines(data.get("end_gcode", []), f"{where}: end_gcode"),
        temperatures=_temperatures(data.get("temperatures", {}), f"{where}: temperatures"),
        home_on_start=data.get("home_on_start", False),
        tool_lengths=_tool_lengths(data.get("tool_lengths", {}), f"{where}: tool_lengths"),
        process_switch_s=float(data.get("process_switch_s", DEFAULT_PROCESS_SWITCH_S)),
        platform=data.get("platform", True),
        tool_change_z=(float(data["tool_change_z"]) if _is_number(data.get("tool_change_z"))
                       else _no_tool_change_z(data, where)))


def _tool_lengths(value: dict, where: str) -> tuple[tuple[int, float], ...]:
    out = []
    for tool, length in value.items():
        if not (str(tool).isdigit() and _is_number(length)):
            raise KinematicsError(f"{where}: {tool!r}: {length!r} must map a tool number to a "
                                  "length in mm (relative to the tool the pivots are measured from)")
        out.append((int(tool), float(length)))
    return tuple(sorted(out))


def _no_tool_change_z(data: dict, where: str) -> float | None:
    """None when the machine file names no tool-change height; an error when it names one
    that is not a number."""
    if "tool_change_z" in data:
        raise KinematicsError(f"{where}: tool_change_z = {data['tool_change_z']!r} is not a number")
    return None


def _gcode_lines(value: list, where: str) -> tuple[str, ...]:
    """Machine-carried G-code: one command per string, no line breaks or comments (the
    dialect writes comments its own way)."""
    for line in value:
        if not isinstance(line, str) or any(c in line for c in "\n\r;()"):
            raise KinematicsError(f"{where}: {line!r} must be one G-code command without "
                                  "line breaks or comments")
    return tuple(line.strip() for line in value if line.strip())


def _temperatures(value: dict, where: str) -> tuple[tuple[str, float], ...]:
    out = []
    for heater, celsius in value.items():
        if heater not in _HEATERS or not _is_number(celsius) or not 0 < celsius < 500:
            raise KinematicsError(f"{where}.{heater} = {celsius!r}: heaters are {_HEATERS}, "
                                  "each a temperature in °C between 0 and 500")
        out.append((heater, float(celsius)))
    return tuple(out)


def _is_number(value: object) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _check_keys(data: dict, schema: dict, required: set, where: str) -> None:
    missing = sorted(required - set(data))
    if missing:
        raise KinematicsError(f"{where}: missing key(s) {', '.join(missing)}")
    unknown = sorted(set(data) - set(schema))
    if unknown:
        raise KinematicsError(f"{where}: unknown key(s) {', '.join(unknown)}")
    for key, value in data.items():
        wanted = schema[key]
        if not isinstance(value, wanted) or isinstance(value, bool) and wanted is not bool:
            raise KinematicsError(f"{where}: {key} = {value!r} has the wrong type")


def _vector(value: object, where: str) -> np.ndarray:
    if not (isinstance(value, list) and len(value) == 3 and all(_is_number(v) for v in value)):
        raise KinematicsError(f"{where} = {value!r} must be a list of three numbers")
    return np.array(value, dtype=float)


def _unit(value: object, where: str) -> np.ndarray:
    vector = _vector(value, where)
    norm = float(np.linalg.norm(vector))
    if norm < ZERO_LENGTH:
        raise KinematicsError(f"{where} = {value!r} is a zero vector")
    return vector / norm


def _limits(value: object, where: str) -> tuple[float, float]:
    if not (isinstance(value, list) and len(value) == 2 and all(_is_number(v) for v in value)
            and value[0] < value[1]):
        raise KinematicsError(f"{where} = {value!r} must be [low, high] with low < high")
    return float(value[0]), float(value[1])


def _linear_axis(axes: dict, name: str, where: str) -> LinearAxis:
    entry = axes.get(name)
    if not isinstance(entry, dict):
        raise KinematicsError(f"{where}: linear_axes.{name} is missing")
    _check_keys(entry, {"limits": list, "moves": str}, {"limits", "moves"},
                f"{where}: linear_axes.{name}")
    if entry["moves"] not in ("tool", "table"):
        raise KinematicsError(f"{where}: linear_axes.{name}.moves must be 'tool' or 'table'")
    return LinearAxis(name, _limits(entry["limits"], f"{where}: linear_axes.{name}.limits"),
                      entry["moves"])


def _rotary_axis(entry: object, index: int, where: str) -> RotaryAxis:
    here = f"{where}: rotary_axes[{index}]"
    if not isinstance(entry, dict):
        raise KinematicsError(f"{here} must be an object")
    _check_keys(entry, _ROTARY_KEYS, {"name", "on", "direction", "pivot", "continuous"}, here)
    if entry["name"] not in ROTARY_NAMES or entry["on"] not in ("table", "head"):
        raise KinematicsError(f"{here}: name must be A, B or C and on 'table' or 'head' "
                              f"(got {entry['name']!r}, {entry['on']!r})")
    continuous = entry["continuous"]
    wrap = entry.get("wrap", False)
    if continuous == ("limits" in entry):
        raise KinematicsError(f"{here}: give limits exactly when the axis is not continuous")
    if wrap and not continuous:
        raise KinematicsError(f"{here}: wrap needs a continuous axis")
    limits = None
    if not continuous:
        low, high = _limits(entry["limits"], f"{here}.limits")
        limits = (math.radians(low), math.radians(high))
    return RotaryAxis(entry["name"], entry["on"], _unit(entry["direction"], f"{here}.direction"),
                      _vector(entry["pivot"], f"{here}.pivot"), limits, continuous, wrap)
