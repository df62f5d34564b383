"""`decompose PART [--json plan.json] [--step-dir DIR]`: support-free sub-parts and their order."""
from __future__ import annotations

import argparse
import math
import sys


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("part", help="STEP, BREP, IGES or FCStd file, or sample:NAME (built-in)")
    parser.add_argument("--overhang", type=float, default=45.0,
                        help="allowed overhang from the build direction in degrees (default 45)")
    parser.add_argument("--method", choices=("true-direction", "published"),
                        default="true-direction",
                        help="centroidal axis: follow inclined members, or nearest ±X/±Y/±Z")
    parser.add_argument("--tool", default="fdm_0p4",
                        help="tool id whose envelope is checked for collisions (default fdm_0p4)")
    parser.add_argument("--no-collision", action="store_true",
                        help="skip the tool collision check when ordering")
    parser.add_argument("--root", default="auto",
                        help="build direction of the first sub-part: 'auto' (+Z unless turning "
                             "the part whole leaves less overhang) or x,y,z (default auto)")
    parser.add_argument("--json", metavar="FILE", help="write the plan (with the axis) as JSON")
    parser.add_argument("--step-dir", metavar="DIR", help="write one STEP file per sub-part here")


def run(args: argparse.Namespace) -> int:
    from freecad_conformal.decomposition.decompose import decompose
    from freecad_conformal.geometry.samples import load_part
    from freecad_conformal.jobs.export import plan_table, write_plan

    if args.step_dir:                   # before the work: the folder's parent must exist
        from freecad_conformal.fileio import make_output_folder

        make_output_folder(args.step_dir)
    shape, _ = load_part(args.part)
    plan = decompose(shape, overhang_angle=math.radians(args.overhang), tool=args.tool,
                     method=args.method, check_collisions=not args.no_collision,
                     root_direction=_root(args.root))
    sys.stdout.write(plan_table(plan))
    written = write_plan(plan, json_path=args.json, step_dir=args.step_dir)
    for path in written:
        print(f"wrote {path}")
    return 0


def _root(text: str):
    """'auto', 'as placed' or a direction x,y,z, read as the plan's root setting."""
    from freecad_conformal.settings.plan import ROOT

    return ROOT.check(text)
