"""Settings of exact sections (`sections` command, the GUI's Sections object): planar layers
along a direction, or coaxial cylinders about an axis."""
from __future__ import annotations

import math
from dataclasses import replace
from typing import Any, Mapping

from freecad_conformal.settings.schema import Setting, SettingError
from freecad_conformal.tolerances import DEFAULT_CHORD_TOLERANCE, ROUNDING_SLACK

MODES = ("planar", "cylindrical")

_SETTINGS: tuple[Setting, ...] = (
    Setting("mode", "choice", "planar", "mode", "planar layers along the direction, or "
            "coaxial cylinders about the axis through the axis point along the direction",
            group="sections", choices=MODES),
    Setting("direction", "direction", (0.0, 0.0, 1.0), "direction",
            "build direction; in cylindrical mode the cylinders' axis", group="sections"),
    Setting("layer", "length", 1.0, "layer height", "uniform layer spacing (planes at "
            "mid-layer)", group="planar", flag="--layer-height", aliases=("--layer",),
            prop="LayerHeight", minimum=0.0, open_minimum=True),
    Setting("heights", "lengths", None, "heights", "explicit heights along the direction "
            "(comma-separated) instead of the uniform spacing", group="planar",
            derived="the layer height's uniform spacing"),
    Setting("axis_point", "point", (0.0, 0.0, 0.0), "axis point", "a point on the cylinders' "
            "axis", group="cylindrical"),
    Setting("radii", "lengths", None, "radii", "explicit cylinder radii (comma-separated)",
            group="cylindrical", minimum=0.0, open_minimum=True,
            derived="radius start to radius end by radius step"),
    Setting("radius_start", "length", 1.0, "first radius", "first cylinder radius",
            group="cylindrical", minimum=0.0, open_minimum=True),
    Setting("radius_end", "length", 10.0, "last radius", "last cylinder radius",
            group="cylindrical", minimum=0.0, open_minimum=True),
    Setting("radius_step", "length", 1.0, "radial spacing", "spacing of the cylinders",
            group="cylindrical", minimum=0.0, open_minimum=True),
    Setting("chord", "length", DEFAULT_CHORD_TOLERANCE, "chord tolerance",
            "largest distance of the loops' polygons from the exact section", group="sections",
            prop="ChordTolerance", minimum=0.0, open_minimum=True),
    Setting("workers", "int", 1, "workers", "processes cutting sections at once",
            group="sections", prop="", minimum=1),
)

#: A setting grouped under a mode applies in that mode only (the task panel hides the rest).
SECTIONS_SETTINGS: tuple[Setting, ...] = tuple(
    replace(s, only_when=("mode", (s.group,))) if s.group in MODES else s for s in _SETTINGS)


def section_radii(values: Mapping[str, Any]) -> tuple[float, ...]:
    """The cylinder radii of checked values: the explicit list, else start to end by step
    (both ends included)."""
    if values["radii"]:
        return tuple(values["radii"])
    start, end, step = values["radius_start"], values["radius_end"], values["radius_step"]
    if end < start:
        raise SettingError(f"last radius (--radius-end / RadiusEnd) {end:g} mm is below the "
                           f"first radius (--radius-start / RadiusStart) {start:g} mm")
    count = int(math.floor((end - start) / step + ROUNDING_SLACK)) + 1
    return tuple(start + k * step for k in range(count))
