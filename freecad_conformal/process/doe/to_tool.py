"""Saving a DOE optimum into a tool's process settings for one material."""
from __future__ import annotations

from freecad_conformal.errors import ProcessError
from freecad_conformal.process.doe.analysis import Analysis
from freecad_conformal.process.doe.design import Design
from freecad_conformal.process.library import ToolLibrary
from freecad_conformal.process.process_settings import ProcessSettings

_SECONDS_PER_MINUTE = 60.0
#: Speed units a response may be scaled to; the feed is stored in mm/min.
_TO_MM_PER_MIN = {"mm/s": _SECONDS_PER_MINUTE, "mm/min": 1.0}


def setting_parameters(result: Analysis, design: Design | None) -> dict[str, float | str]:
    """The optimum's factor levels named by label and unit ('UV power [mW]': 495)."""
    parameters: dict[str, float | str] = {}
    for name, value in result.settings.items():
        factor = design.factor(name) if design else None
        key = name
        if factor is not None and factor.label:
            key = f"{factor.label} [{factor.unit}]" if factor.unit else factor.label
        parameters[key] = value
    return parameters


def save_optimum(library: ToolLibrary, tool_id: str, material: str, result: Analysis,
                 design: Design | None = None, study: str = "") -> ProcessSettings:
    """Store the optimum as the tool's settings for `material` (replacing earlier ones) and
    return them. The predicted response becomes the feed when it was scaled to a speed
    (response unit mm/s or mm/min); the factor levels go into `parameters`. The library is
    changed in memory; call `library.save()` to write it."""
    if not material.strip():
        raise ProcessError("a material name is needed to store process settings")
    tool = library.get(tool_id).copy()
    feed = None
    if result.predicted_real is not None:
        factor = _TO_MM_PER_MIN.get(result.response_unit)
        if factor is None:
            raise ProcessError(f"response unit {result.response_unit!r} is not a speed "
                               f"({', '.join(_TO_MM_PER_MIN)}); the prediction cannot be a feed")
        feed = result.predicted_real * factor
    previous = tool.settings.get(material, ProcessSettings())
    source = (f"DOE {study or result.source}: {result.optimum.goal}-the-better optimum, "
              f"predicted {result.optimum.mean:.5g}"
              + (f" = {result.predicted_real:.4g} {result.response_unit}" if feed else ""))
    settings = ProcessSettings(feed=feed if feed is not None else previous.feed,
                               width=previous.width, power=previous.power,
                               layer_height=previous.layer_height, dp=previous.dp, ec=previous.ec,
                               parameters={**previous.parameters,
                                           **setting_parameters(result, design)},
                               source=source)
    tool.settings[material] = settings
    library.set(tool)
    return settings
