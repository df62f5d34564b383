"""`sections PART [--layer-height 0.2 | --heights ... | --radii ...] [--direction 0,0,1]
[--json out.json]`: a section report; the settings are settings/sections.py's."""
from __future__ import annotations

import argparse
import sys

from freecad_conformal.settings.sections import SECTIONS_SETTINGS


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from freecad_conformal.settings.cli import add_arguments as add_settings

    parser.add_argument("part", help="STEP, BREP, IGES or FCStd file")
    add_settings(parser, SECTIONS_SETTINGS)
    parser.add_argument("--json", metavar="FILE", help="write the documented JSON report here")


def run(args: argparse.Namespace) -> int:
    from freecad_conformal.geometry.report import section_report
    from freecad_conformal.settings.cli import values_from_args
    from freecad_conformal.settings.schema import SettingError, validate
    from freecad_conformal.settings.sections import section_radii

    if args.layer is not None and args.heights is not None:
        raise SettingError("give the layer height (--layer-height) or explicit --heights, not both")
    values = values_from_args(args, SECTIONS_SETTINGS)
    radii_given = any(getattr(args, key) is not None
                      for key in ("radii", "radius_start", "radius_end", "radius_step"))
    if args.mode is None and radii_given:
        values["mode"] = "cylindrical"            # --radii alone asks for cylinders
    values = validate(SECTIONS_SETTINGS, values)
    cylindrical = values["mode"] == "cylindrical"
    if cylindrical and (args.layer is not None or args.heights is not None):
        raise SettingError("--layer-height and --heights are for planar sections; cylindrical "
                           "sections take --radii or --radius-start/--radius-end/--radius-step")
    report = section_report(
        args.part, layer=values["layer"], heights=values["heights"],
        radii=section_radii(values) if cylindrical else None, direction=values["direction"],
        axis_point=values["axis_point"], chord=values["chord"], workers=values["workers"],
        json_path=args.json, show_progress=True)
    sys.stdout.write(report.table())
    if args.json:
        print(f"wrote {args.json}")
    return 0
