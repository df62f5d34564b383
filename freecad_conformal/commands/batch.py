"""`batch INPUTS... --machine NAME --tool ID -o DIR`: plan and post many parts.

INPUTS are STEP, BREP, IGES or FCStd files, folders or globs (quote globs to let Conformal
expand them, `**` included); every solid body of an FCStd is its own part (`file#Label`).
Writes DIR/<part>.gcode per part and DIR/batch-report.csv/.json (part, status, sub-parts,
layers, material, time, G-code bytes, error). Exit code 1 when any part failed.
"""
from __future__ import annotations

import argparse
import math
import sys

from freecad_conformal.commands.plan import add_plan_settings

def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("inputs", nargs="+", metavar="INPUT",
                        help="part files, folders or globs (STEP, BREP, IGES, FCStd)")
    parser.add_argument("-o", "--output-dir", dest="out_dir", required=True,
                        help="folder for the G-code files and the report")
    parser.add_argument("--suffix", default=".gcode", help="G-code file suffix (default .gcode)")
    run = parser.add_argument_group("where the parts run")
    run.add_argument("--workers", type=int, default=1,
                     help="parallel processes on this machine (default 1; 0 plans in this process)")
    run.add_argument("--dask", metavar="ADDRESS",
                     help="send the parts to this Dask scheduler (e.g. tcp://host:8786) instead")
    run.add_argument("--start-method", choices=("spawn", "fork", "forkserver"),
                     help="how local workers start (default spawn; fork inside FreeCAD 0.20)")
    run.add_argument("--time-limit", type=float, default=None, metavar="S",
                     help="seconds one part may take on a local worker before it is stopped "
                          "and reported as failed (default 3600; 0: no limit)")
    add_plan_settings(parser)


#: Batch arguments that are not plan settings.
BATCH_ONLY = ("inputs", "out_dir", "suffix", "workers", "dask", "start_method", "time_limit")
#: Plan arguments that name one part's files, which batch names itself.
PLAN_PER_FILE = ("part", "output", "png", "summary", "toolpath", "report")
#: Plan arguments batch does not offer: mandrel builds are planned one part at a time.
PLAN_ONLY = ("mandrel", "mapping")


def plan_options(args: argparse.Namespace):
    """PlanOptions from the batch arguments, through the same schema as `plan`."""
    from freecad_conformal.commands import plan

    return plan.options_from(args)


def run(args: argparse.Namespace) -> int:
    from freecad_conformal.jobs.batch.report import table
    from freecad_conformal.jobs.batch.run import run_batch
    from freecad_conformal.errors import ConformalError
    from freecad_conformal.progress import Progress

    from freecad_conformal.jobs.batch.run import PART_TIME_LIMIT

    if args.workers < 0:
        raise ConformalError(f"--workers must be 0 or more, got {args.workers}")
    limit = PART_TIME_LIMIT if args.time_limit is None else args.time_limit
    if not (limit >= 0 and math.isfinite(limit)):
        raise ConformalError(f"--time-limit must be 0 (none) or a number of seconds, got {limit}")
    options = plan_options(args)
    result = run_batch(args.inputs, options, args.out_dir, workers=args.workers, dask=args.dask,
                       start_method=args.start_method, suffix=args.suffix,
                       make_progress=lambda total: Progress(total, label="batch"),
                       time_limit=limit or None)
    print(table(result.rows), end="")
    written = sum(row["gcode"] is not None for row in result.rows)
    print(f"wrote {written} G-code files and {result.csv_path}, {result.json_path}", file=sys.stderr)
    return 1 if result.failed else 0
