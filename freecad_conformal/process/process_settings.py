"""Process settings of one tool with one material (speeds, widths, power, curing constants)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from freecad_conformal.errors import ProcessError
from freecad_conformal.process import json_fields as schema
from freecad_conformal.process.curing_fit import CurePoint

#: JSON keys of the calibration lists: measured lines (tool moving across its axis) and rods
#: (tool moving along it), each point {"power_w", "speed_mm_s", "width", "source"}.
CALIBRATION_KEYS = {"line_curing": "line_points", "point_curing": "rod_points"}

_NUMBER_KEYS = {
    # JSON key -> (attribute, meaning for the message-free reader of the file)
    "feed_mm_min": "feed",          # working speed along the path (mm/min)
    "width": "width",               # line / bead / cut width (mm)
    "power_w": "power",             # source power (W)
    "layer_height": "layer_height", # accumulation step (mm)
    "dp": "dp",                     # resin penetration depth Dp (mm), curing only
    "ec_mj_cm2": "ec",              # resin critical exposure Ec (mJ/cm²), curing only
}


@dataclass
class ProcessSettings:
    """Settings for one material. Any field may be unknown (None). `parameters` holds the
    other named settings (temperatures, gap, strategy...) as numbers or text; `source` says
    where the values come from (a datasheet, a DOE study)."""

    feed: float | None = None
    width: float | None = None
    power: float | None = None
    layer_height: float | None = None
    dp: float | None = None
    ec: float | None = None
    parameters: dict[str, float | str] = field(default_factory=dict)
    source: str = ""
    line_points: list[CurePoint] = field(default_factory=list)
    rod_points: list[CurePoint] = field(default_factory=list)

    @classmethod
    def from_dict(cls, data: dict, where: str) -> "ProcessSettings":
        schema.check_keys(data, tuple(_NUMBER_KEYS) + ("parameters", "source")
                          + tuple(CALIBRATION_KEYS), where)
        values: dict[str, Any] = {
            attr: schema.number(data, key, where, default=None, minimum=0, exclusive_minimum=True)
            for key, attr in _NUMBER_KEYS.items()
        }
        parameters = schema.mapping(data, "parameters", where)
        for name, value in parameters.items():
            if isinstance(value, bool) or not isinstance(value, (int, float, str)):
                raise ProcessError(f"{where}: parameter {name!r} must be a number or text, "
                                   f"got {value!r}")
        calibration: dict[str, Any] = {attr: _points(data.get(key, []), f"{where} {key}")
                       for key, attr in CALIBRATION_KEYS.items()}
        return cls(**values, parameters=parameters,
                   source=schema.text(data, "source", where, default="", non_empty=False),
                   **calibration)

    def to_dict(self) -> dict:
        data: dict[str, Any] = {}
        for key, attr in _NUMBER_KEYS.items():
            value = getattr(self, attr)
            if value is not None:
                data[key] = value
        if self.parameters:
            data["parameters"] = dict(self.parameters)
        if self.source:
            data["source"] = self.source
        for key, attr in CALIBRATION_KEYS.items():
            if getattr(self, attr):
                data[key] = [p.to_dict() for p in getattr(self, attr)]
        return data


def _points(raw: Any, where: str) -> list[CurePoint]:
    if not isinstance(raw, list):
        raise ProcessError(f"{where}: expected a list of calibration points, got {raw!r}")
    points = []
    for k, entry in enumerate(raw):
        here = f"{where} point {k + 1}"
        schema.check_keys(entry, ("power_w", "speed_mm_s", "width", "source"), here)
        point = CurePoint(schema.number(entry, "power_w", here, minimum=0, exclusive_minimum=True),
                          schema.number(entry, "speed_mm_s", here, minimum=0,
                                        exclusive_minimum=True),
                          schema.number(entry, "width", here, minimum=0),
                          schema.text(entry, "source", here, default="", non_empty=False))
        points.append(point)
    return points
