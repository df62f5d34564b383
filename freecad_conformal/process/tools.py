"""The tool model: UV light guides, FDM nozzles, laser powder nozzles and milling cutters.

Units inside are the project's: millimetres, radians, mm/min for feeds, watts for power.
The JSON form (`Tool.to_dict` / `Tool.from_dict`) names non-mm units in its keys
(`max_tilt_deg`, `bend_angle_deg`, `feed_mm_min`, `power_w`) so a user editing a file
cannot mistake them; every other length is in mm.
"""
from __future__ import annotations

import copy
import math
import re
from dataclasses import dataclass, field
from typing import Any

from freecad_conformal.errors import ProcessError
from freecad_conformal.process import json_fields as schema
from freecad_conformal.process.process_settings import ProcessSettings

KINDS = ("uv_light_guide", "fdm_nozzle", "laser_nozzle", "end_mill")
HEADS = ("straight", "angled")
MASK_SHAPES = ("disk", "square", "star", "heart", "custom")
#: Tool ids become file names in the user library, so they are kept to safe characters.
ID_PATTERN = re.compile(r"^[a-z0-9][a-z0-9_.-]{0,63}$")


def _degrees(radians: float) -> float:
    """Degrees for the JSON file, rounded to 1e-9° so 60° does not come back as 59.99999…"""
    return round(math.degrees(radians), 9)


@dataclass
class Envelope:
    """Collision envelope: a cone tip widening from `tip_diameter` at the tool point to
    `body_diameter` over `tip_length`, then a cylinder of `body_diameter` for `body_length`."""

    tip_diameter: float
    tip_length: float
    body_diameter: float
    body_length: float

    def radius_at(self, height: float) -> float:
        """Envelope radius at `height` mm above the tool point along the tool axis (0 outside)."""
        if height < 0 or height > self.tip_length + self.body_length:
            return 0.0
        if height >= self.tip_length:
            return self.body_diameter / 2
        return (self.tip_diameter + (self.body_diameter - self.tip_diameter)
                * height / self.tip_length) / 2

    @classmethod
    def from_dict(cls, data: dict, where: str) -> "Envelope":
        schema.check_keys(data, ("tip_diameter", "tip_length", "body_diameter", "body_length"), where)
        env = cls(schema.number(data, "tip_diameter", where, minimum=0, exclusive_minimum=True),
                  schema.number(data, "tip_length", where, minimum=0),
                  schema.number(data, "body_diameter", where, minimum=0, exclusive_minimum=True),
                  schema.number(data, "body_length", where, minimum=0, exclusive_minimum=True))
        if env.body_diameter < env.tip_diameter:
            raise ProcessError(f"{where}: body_diameter {env.body_diameter:g} is smaller than "
                               f"tip_diameter {env.tip_diameter:g}")
        return env

    def to_dict(self) -> dict:
        return {"tip_diameter": self.tip_diameter, "tip_length": self.tip_length,
                "body_diameter": self.body_diameter, "body_length": self.body_length}


@dataclass
class Mask:
    """A physical mask on a UV tip: it cures its own shape as a texture. `size` is the
    outer dimension (mm); `outline` (closed polygon, mm) only for the custom shape."""

    shape: str
    size: float
    outline: list[tuple[float, float]] = field(default_factory=list)

    @classmethod
    def from_dict(cls, data: dict, where: str) -> "Mask":
        schema.check_keys(data, ("shape", "size", "outline"), where)
        shape = schema.text(data, "shape", where, choices=MASK_SHAPES)
        size = schema.number(data, "size", where, minimum=0, exclusive_minimum=True)
        raw = data.get("outline", [])
        if shape != "custom":
            if raw:
                raise ProcessError(f"{where}: an outline is only allowed for shape 'custom', "
                                   f"not {shape!r}")
            return cls(shape, size)
        if not isinstance(raw, list) or len(raw) < 3:
            raise ProcessError(f"{where}: a custom mask needs an outline of at least 3 [x, y] "
                               f"points, got {raw!r}")
        points = []
        for i, point in enumerate(raw):
            if (not isinstance(point, list) or len(point) != 2
                    or not all(isinstance(v, (int, float)) and not isinstance(v, bool)
                               and math.isfinite(v) for v in point)):
                raise ProcessError(f"{where}: outline point {i} must be [x, y] numbers, got {point!r}")
            points.append((float(point[0]), float(point[1])))
        area2 = sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(points, points[1:] + points[:1]))
        if abs(area2) <= 1e-12:
            raise ProcessError(f"{where}: the custom outline encloses no area")
        return cls(shape, size, points)

    def to_dict(self) -> dict:
        data: dict[str, Any] = {"shape": self.shape, "size": self.size}
        if self.outline:
            data["outline"] = [list(p) for p in self.outline]
        return data


@dataclass
class UvGuide:
    """UV curing light guide: spot (core) diameter B of the curing model, the smallest line
    it cures reliably, the power levels of its source (W) and an optional mask."""

    spot_diameter: float
    min_line_width: float
    power_levels: list[float] = field(default_factory=list)
    mask: Mask | None = None

    @classmethod
    def from_dict(cls, data: dict, where: str) -> "UvGuide":
        schema.check_keys(data, ("spot_diameter", "min_line_width", "power_levels_w", "mask"), where)
        mask = data.get("mask")
        return cls(schema.number(data, "spot_diameter", where, minimum=0, exclusive_minimum=True),
                   schema.number(data, "min_line_width", where, minimum=0, exclusive_minimum=True),
                   schema.number_list(data, "power_levels_w", where, minimum=0,
                                      exclusive_minimum=True),
                   Mask.from_dict(mask, f"{where} mask") if mask is not None else None)

    def to_dict(self) -> dict:
        data: dict[str, Any] = {"spot_diameter": self.spot_diameter,
                                "min_line_width": self.min_line_width,
                                "power_levels_w": list(self.power_levels)}
        if self.mask is not None:
            data["mask"] = self.mask.to_dict()
        return data


@dataclass
class FdmNozzle:
    """FDM hot end: the heater block (a box, mm) sits `nozzle_length` above the nozzle tip;
    it is what collides with printed walls when printing steeply (METHODS section 4)."""

    heater_block_width: float
    heater_block_depth: float
    heater_block_height: float
    nozzle_length: float

    _KEYS = ("heater_block_width", "heater_block_depth", "heater_block_height", "nozzle_length")

    @classmethod
    def from_dict(cls, data: dict, where: str) -> "FdmNozzle":
        schema.check_keys(data, cls._KEYS, where)
        return cls(*(schema.number(data, key, where, minimum=0, exclusive_minimum=True)
                     for key in cls._KEYS))

    def to_dict(self) -> dict:
        return {key: getattr(self, key) for key in self._KEYS}


@dataclass
class LaserNozzle:
    """Laser powder deposition nozzle: laser spot on the part, stand-off distance, source power."""

    spot_diameter: float
    standoff: float
    max_power: float

    @classmethod
    def from_dict(cls, data: dict, where: str) -> "LaserNozzle":
        schema.check_keys(data, ("spot_diameter", "standoff", "max_power_w"), where)
        return cls(schema.number(data, "spot_diameter", where, minimum=0, exclusive_minimum=True),
                   schema.number(data, "standoff", where, minimum=0, exclusive_minimum=True),
                   schema.number(data, "max_power_w", where, minimum=0, exclusive_minimum=True))

    def to_dict(self) -> dict:
        return {"spot_diameter": self.spot_diameter, "standoff": self.standoff,
                "max_power_w": self.max_power}


@dataclass
class Cutter:
    """Milling cutter: flute count and length, corner radius (0 for a flat end mill); a
    tapered cutter (a V-bit) has the included angle of its cone, `taper_deg`, and the flat
    at its point, `tip_diameter`: its cone widens from the tip to the tool's diameter."""

    flutes: int
    flute_length: float
    corner_radius: float = 0.0
    taper_deg: float = 0.0
    tip_diameter: float = 0.0

    @classmethod
    def from_dict(cls, data: dict, where: str) -> "Cutter":
        schema.check_keys(data, ("flutes", "flute_length", "corner_radius", "taper_deg",
                                 "tip_diameter"), where)
        cutter = cls(schema.integer(data, "flutes", where, minimum=1),
                     schema.number(data, "flute_length", where, minimum=0, exclusive_minimum=True),
                     schema.number(data, "corner_radius", where, default=0.0, minimum=0),
                     schema.number(data, "taper_deg", where, default=0.0, minimum=0, maximum=179),
                     schema.number(data, "tip_diameter", where, default=0.0, minimum=0))
        if cutter.tip_diameter and not cutter.taper_deg:
            raise ProcessError(f"{where}: tip_diameter {cutter.tip_diameter:g} is for a tapered "
                               "cutter; give taper_deg too")
        if cutter.taper_deg and cutter.corner_radius:
            raise ProcessError(f"{where}: a tapered cutter takes tip_diameter, not corner_radius")
        return cutter

    def cone_length(self, diameter: float) -> float:
        """How far (mm) from the tip a tapered cutter's cone reaches `diameter` (0 when not
        tapered)."""
        if not self.taper_deg:
            return 0.0
        return 0.5 * (diameter - self.tip_diameter) / math.tan(math.radians(0.5 * self.taper_deg))

    def to_dict(self) -> dict:
        data = {"flutes": self.flutes, "flute_length": self.flute_length,
                "corner_radius": self.corner_radius}
        if self.taper_deg:
            data.update(taper_deg=self.taper_deg, tip_diameter=self.tip_diameter)
        return data


#: kind -> (JSON key of its kind-specific block, class of that block)
KIND_BLOCKS: dict[str, tuple[str, Any]] = {   # (JSON key, block class with from_dict)
    "uv_light_guide": ("uv", UvGuide),
    "fdm_nozzle": ("fdm", FdmNozzle),
    "laser_nozzle": ("laser", LaserNozzle),
    "end_mill": ("mill", Cutter),
}


@dataclass
class Tool:
    """One tool of the library.

    `diameter` is the working diameter dt that enters the curvature rule (the guide's tip, the
    nozzle bore, the cutter); `max_tilt` is W, the largest rotation of the tool from the build
    direction; an angled head is bent by `bend_angle`. `settings` maps a material name to its
    process settings; `spec` is the kind-specific block (UvGuide, FdmNozzle, ...).
    """

    id: str
    name: str
    kind: str
    diameter: float
    envelope: Envelope
    spec: UvGuide | FdmNozzle | LaserNozzle | Cutter
    max_tilt: float = math.pi / 2
    head: str = "straight"
    bend_angle: float = 0.0
    settings: dict[str, ProcessSettings] = field(default_factory=dict)
    notes: str = ""

    def reachable_tilt(self) -> tuple[float, float]:
        """Tool-axis tilts (rad) this tool reaches: [0, W] straight, [bend − W, bend + W] angled."""
        if self.head == "angled":
            return max(0.0, self.bend_angle - self.max_tilt), self.bend_angle + self.max_tilt
        return 0.0, self.max_tilt

    def copy(self) -> "Tool":
        return copy.deepcopy(self)

    def validate(self) -> None:
        """Raise ProcessError if the tool (possibly edited in memory) is no longer valid."""
        Tool.from_dict(self.to_dict(), f"tool {self.id!r}")

    def to_dict(self) -> dict:
        block_key = KIND_BLOCKS[self.kind][0] if self.kind in KIND_BLOCKS else "spec"
        data: dict[str, Any] = {
            "id": self.id, "name": self.name, "kind": self.kind, "diameter": self.diameter,
            "head": self.head, "max_tilt_deg": _degrees(self.max_tilt),
            "envelope": self.envelope.to_dict(), block_key: self.spec.to_dict(),
            "settings": {name: s.to_dict() for name, s in self.settings.items()},
        }
        if self.head == "angled":
            data["bend_angle_deg"] = _degrees(self.bend_angle)
        if self.notes:
            data["notes"] = self.notes
        return data

    @classmethod
    def from_dict(cls, data: dict, source: str = "") -> "Tool":
        """Build and check a tool from its JSON form; errors name the tool and `source`."""
        raw_id = data.get("id") if isinstance(data, dict) else None
        where = f"tool {raw_id!r}" + (f" ({source})" if source else "")
        tool_id = schema.text(data if isinstance(data, dict) else {}, "id", where)
        if not ID_PATTERN.match(tool_id):
            raise ProcessError(f"{where}: id must be lower-case letters, digits, '_', '-' or '.' "
                               f"(at most 64, used as a file name), got {tool_id!r}")
        kind = schema.text(data, "kind", where, choices=KINDS)
        block_key, block_class = KIND_BLOCKS[kind]
        schema.check_keys(data, ("id", "name", "kind", "diameter", "head", "max_tilt_deg",
                                 "bend_angle_deg", "envelope", "settings", "notes", block_key), where)
        head = schema.text(data, "head", where, default="straight", choices=HEADS)
        bend = schema.number(data, "bend_angle_deg", where, default=0.0, minimum=0, maximum=180)
        if head == "angled" and bend <= 0:
            raise ProcessError(f"{where}: an angled head needs bend_angle_deg > 0, got {bend:g}")
        if head == "straight" and bend != 0:
            raise ProcessError(f"{where}: a straight head cannot have bend_angle_deg {bend:g}")
        if block_key not in data:
            raise ProcessError(f"{where}: a {kind} needs its {block_key!r} block")
        settings = {}
        for material, values in schema.mapping(data, "settings", where).items():
            settings[material] = ProcessSettings.from_dict(values, f"{where} settings {material!r}")
        tool = cls(
            id=tool_id, name=schema.text(data, "name", where, default=tool_id), kind=kind,
            diameter=schema.number(data, "diameter", where, minimum=0, exclusive_minimum=True),
            envelope=Envelope.from_dict(schema.mapping(data, "envelope", where), f"{where} envelope"),
            spec=block_class.from_dict(schema.mapping(data, block_key, where), f"{where} {block_key}"),
            max_tilt=math.radians(schema.number(data, "max_tilt_deg", where, default=90.0,
                                                minimum=0, maximum=180)),
            head=head, bend_angle=math.radians(bend), settings=settings,
            notes=schema.text(data, "notes", where, default="", non_empty=False),
        )
        if isinstance(tool.spec, Cutter) and tool.spec.taper_deg:
            cone = tool.spec.cone_length(tool.diameter)
            if tool.spec.tip_diameter >= tool.diameter:
                raise ProcessError(f"{where}: tip_diameter {tool.spec.tip_diameter:g} must be "
                                   f"smaller than the tool diameter {tool.diameter:g}")
            if cone > tool.spec.flute_length + 1e-9:
                raise ProcessError(f"{where}: the {tool.spec.taper_deg:g}° cone reaches the "
                                   f"diameter {tool.diameter:g} {cone:.2f} mm from the tip, past "
                                   f"the flute_length {tool.spec.flute_length:g}")
        if tool.envelope.tip_diameter < tool.diameter:
            raise ProcessError(f"{where}: envelope tip_diameter {tool.envelope.tip_diameter:g} is "
                               f"smaller than the tool diameter {tool.diameter:g}")
        return tool
