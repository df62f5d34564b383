"""`mandrel PART --machine rotary_mandrel [--layer-height 0.3] -o out.gcode`: a build on a
rotating mandrel (METHODS section 5), unrolled cylindrical layers, G-code for a true rotary
axis or for the rotation driven as a linear axis scaled at the first-layer radius. The
settings are settings/mandrel.py's."""
from __future__ import annotations

import argparse
import math
import sys

from freecad_conformal.settings.mandrel import MANDREL_SETTINGS


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from freecad_conformal.settings.cli import add_arguments as add_settings

    parser.add_argument("part", help="STEP, BREP, IGES or FCStd file placed around the machine's "
                        "rotary axis")
    parser.add_argument("-o", "--output", required=True, help="G-code file to write")
    parser.add_argument("--toolpath", help="also save the neutral toolpath (.npz) here")
    add_settings(parser, MANDREL_SETTINGS)


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from freecad_conformal.geometry.solids import load_shape
    from freecad_conformal.jobs.mandrel import plan_mandrel
    from freecad_conformal.progress import Progress
    from freecad_conformal.settings.cli import values_from_args
    from freecad_conformal.settings.schema import validate

    values = validate(MANDREL_SETTINGS, values_from_args(args, MANDREL_SETTINGS))
    shape = load_shape(args.part)
    angle = None if values["angle"] is None else math.radians(values["angle"])
    with Progress(0, "sections") as bar:
        def progress(done: int, total: int) -> None:
            bar.total = total
            bar.update(1)
        result = plan_mandrel(shape, values["machine"], values["tool"], values["layer"],
                              args.output, mapping=values["mapping"], width=values["width"],
                              feed=values["feed"], travel_feed=values["travel_feed"],
                              angle=angle, material=values["material"],
                              part=Path(args.part).stem, toolpath_out=args.toolpath,
                              progress=progress)
    print(result.report())
    print(f"wrote {args.output}", file=sys.stderr)
    return 0
