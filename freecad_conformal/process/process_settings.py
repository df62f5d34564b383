"""Process settings of one tool with one material (speeds, widths, power, curing constants)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from freecad_conformal.errors import ProcessError
from freecad_conformal.process import json_fields as schema

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

    @classmethod
    def from_dict(cls, data: dict, where: str) -> "ProcessSettings":
        schema.check_keys(data, tuple(_NUMBER_KEYS) + ("parameters", "source"), where)
        values: dict[str, Any] = {
            attr: schema.number(data, key, where, default=None, minimum=0, exclusive_minimum=True)
            for key, attr in _NUMBER_KEYS.items()
        }
        parameters = schema.mapping(data, "parameters", where)
        for name, value in parameters.items():
            if isinstance(value, bool) or not isinstance(value, (int, float, str)):
                raise ProcessError(f"{where}: parameter {name!r} must be a number or text, "
                                   f"got {value!r}")
        return cls(**values, parameters=parameters,
                   source=schema.text(data, "source", where, default="", non_empty=False))

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
        return data
