"""Typed plan options from settings values: the one place the command line and the Job
object turn user settings (settings/plan.py) into what the planner takes."""
from __future__ import annotations

import math
from typing import Any, Mapping

from freecad_conformal.jobs.plan import HybridOptions, PlanOptions
from freecad_conformal.layers.model import LayerSettings
from freecad_conformal.paths.assemble import Feeds, PathSettings
from freecad_conformal.paths.fill2d import FillSettings
from freecad_conformal.paths.support import SupportSettings
from freecad_conformal.settings.plan import PLAN_SETTINGS, SPEED_ROLES
from freecad_conformal.settings.schema import validate

SECONDS_PER_MINUTE = 60.0
#: The bead width fill settings start from when the material's is used (replaced in
#: jobs/plan.py once the tool and material are known).
PLACEHOLDER_WIDTH = 0.4


def plan_options(values: Mapping[str, Any]) -> PlanOptions:
    """PlanOptions from settings values (checked here: SettingError names the bad one)."""
    v = validate(PLAN_SETTINGS, values)
    angle = None if v["infill_angle"] is None else math.radians(v["infill_angle"])
    fill = FillSettings(bead_width=v["bead_width"] or PLACEHOLDER_WIDTH,
                        perimeters=v["perimeters"], density=v["infill"] / 100.0, angle=angle,
                        seam=v["seam"], bead_model=v["bead_model"],
                        infill_overlap=v["infill_overlap"] / 100.0,
                        solid_below_area=v["solid_below_area"])
    layers = LayerSettings(mode=v["layer_mode"], thickness=v["layer_height"],
                           min_thickness=v["layer_min"], max_thickness=v["layer_max"],
                           max_volume_difference=v["max_volume_difference"],
                           max_cusp=v["max_cusp"], tilt=v["tilt"], workers=v["section_workers"])
    # Speeds given are in mm/s; a derived one keeps the built-in feed, which jobs/plan.py
    # replaces with the material's where the material has one.
    given = {role: v[f"{role}_speed"] * SECONDS_PER_MINUTE for role in SPEED_ROLES
             if v[f"{role}_speed"] is not None}
    paths = PathSettings(fill=fill, feeds=Feeds(**given), top_layers=v["solid_layers"],
                         bottom_layers=v["solid_layers"], min_layer_time=v["min_layer_time"],
                         min_speed=v["min_speed"] * SECONDS_PER_MINUTE, alternate=v["alternate"],
                         support=SupportSettings(enabled=v["support"],
                                                 spacing=v["support_spacing"],
                                                 interface_layers=v["support_interface_layers"],
                                                 bottom_interface_layers=v[
                                                     "support_bottom_interface_layers"],
                                                 bridges=v["support_bridges"]))
    return PlanOptions(machine=v["machine"], tool=v["tool"], material=v["material"],
                       layers=layers, paths=paths, bead_width=v["bead_width"],
                       dialect=v["dialect"], root=v["root"], decompose=v["decompose"],
                       root_search=v["root_search"],
                       objective=v["objective"], jerk=v["jerk"],
                       settings=v, process=v["process"],
                       hybrid=HybridOptions(mill_tools=mill_tool_ids(v["mill_tool"]),
                                            stock=v["stock_allowance"],
                                            fill_holes_below=v["fill_holes_below"],
                                            material_check=v["material_check"]))


def mill_tool_ids(text: str) -> tuple[str, ...]:
    """'endmill_6mm, drill_0p5' -> ('endmill_6mm', 'drill_0p5'); SettingError when empty."""
    from freecad_conformal.settings.schema import SettingError

    ids = tuple(part.strip() for part in str(text).split(",") if part.strip())
    if not ids:
        raise SettingError(f"mill tools (--mill-tool) {text!r} names no tool")
    return ids
