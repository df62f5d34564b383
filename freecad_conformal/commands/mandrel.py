"""`mandrel PART --machine rotary_mandrel [--layer 0.3] -o out.gcode`: a build on a rotating
mandrel (METHODS section 5), unrolled cylindrical layers, G-code for a true rotary axis or
for the rotation driven as a linear axis scaled at the first-layer radius."""
from __future__ import annotations

import argparse
import math
import sys


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("part", help="STEP, BREP, IGES or FCStd file placed around the machine's "
                        "rotary axis")
    parser.add_argument("--machine", default="rotary_mandrel",
                        help="machine with one table rotary axis (default rotary_mandrel)")
    parser.add_argument("--tool", default="fdm_0p4", help="tool id from the library (default fdm_0p4)")
    parser.add_argument("--layer", type=float, default=0.3, help="layer thickness in mm (default 0.3)")
    parser.add_argument("--width", type=float, default=None,
                        help="bead width in mm (default: the tool diameter)")
    parser.add_argument("--feed", type=float, default=2000.0,
                        help="print speed on the surface, mm/min (default 2000, METHODS §5)")
    parser.add_argument("--travel-feed", type=float, default=2400.0,
                        help="travel speed, mm/min (default 2400)")
    parser.add_argument("--angle", type=float, default=None,
                        help="raster angle in degrees in the unrolled plane (default: along "
                        "each layer's long axis, the band inclination for a helix)")
    parser.add_argument("--mapping", choices=("rotary", "linear"), default="rotary",
                        help="rotary: A axis in degrees; linear: rotation driven as Y scaled at "
                        "the first-layer radius, with extrusion and feed compensation")
    parser.add_argument("--material", default="filament", help="material name for the header")
    parser.add_argument("-o", "--output", required=True, help="G-code file to write")
    parser.add_argument("--toolpath", help="also save the neutral toolpath (.npz) here")


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from freecad_conformal.geometry.solids import load_shape
    from freecad_conformal.jobs.mandrel import plan_mandrel
    from freecad_conformal.progress import Progress

    shape = load_shape(args.part)
    angle = None if args.angle is None else math.radians(args.angle)
    with Progress(0, "sections") as bar:
        def progress(done: int, total: int) -> None:
            bar.total = total
            bar.update(1)
        result = plan_mandrel(shape, args.machine, args.tool, args.layer, args.output,
                              mapping=args.mapping, width=args.width, feed=args.feed,
                              travel_feed=args.travel_feed, angle=angle, material=args.material,
                              part=Path(args.part).stem, toolpath_out=args.toolpath,
                              progress=progress)
    print(result.report())
    print(f"wrote {args.output}", file=sys.stderr)
    return 0
