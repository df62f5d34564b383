"""`decompose PART [--json plan.json] [--step-dir DIR]`: support-free sub-parts and their order."""
from __future__ import annotations

import argparse
import sys


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("part", help="STEP, BREP, IGES or FCStd file, or sample:NAME (built-in)")
    from freecad_conformal.settings.cli import add_arguments as add_settings
    from freecad_conformal.settings.decompose import DECOMPOSE_SETTINGS

    add_settings(parser, DECOMPOSE_SETTINGS)
    parser.add_argument("--json", metavar="FILE", help="write the plan (with the axis) as JSON")
    parser.add_argument("--step-dir", metavar="DIR", help="write one STEP file per sub-part here")


def run(args: argparse.Namespace) -> int:
    from freecad_conformal.jobs.decompose import decompose_with
    from freecad_conformal.settings.cli import values_from_args
    from freecad_conformal.settings.decompose import DECOMPOSE_SETTINGS
    from freecad_conformal.geometry.samples import load_part
    from freecad_conformal.jobs.export import plan_table, write_plan

    if args.step_dir:                   # before the work: the folder's parent must exist
        from freecad_conformal.fileio import make_output_folder

        make_output_folder(args.step_dir)
    shape, _ = load_part(args.part)
    plan = decompose_with(shape, values_from_args(args, DECOMPOSE_SETTINGS))
    sys.stdout.write(plan_table(plan))
    written = write_plan(plan, json_path=args.json, step_dir=args.step_dir)
    for path in written:
        print(f"wrote {path}")
    return 0
