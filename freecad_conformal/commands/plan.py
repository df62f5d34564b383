"""`plan PART --machine NAME --tool ID [--layer-height 0.2] -o out.gcode`: the project's main job.

PART is a STEP/BREP/IGES/FCStd file or the name of a built-in sample part (bracket, jack).
Prints the summary, writes the G-code, a PNG preview (paths coloured by sub-part) and,
on request, the summary and the neutral toolpath.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("part", help="part file (STEP, BREP, IGES, FCStd) or a built-in sample name")
    parser.add_argument("-o", "--output", required=True, help="G-code file to write")
    parser.add_argument("--png", help="preview image (default: the output with .png)")
    parser.add_argument("--summary", help="also write the summary to this text file")
    parser.add_argument("--toolpath", help="also save the neutral toolpath (.npz)")
    parser.add_argument("--report", help="also write the plan as JSON (totals, sub-parts, notes "
                        "and every setting used; format conformal.plan/1)")
    add_plan_settings(parser)
    mandrel = parser.add_argument_group("mandrel")
    mandrel.add_argument("--mandrel", action="store_true",
                         help="build around the machine's rotary mandrel in unrolled cylindrical layers "
                              "(machine default rotary_mandrel)")
    from freecad_conformal.settings.cli import add_arguments as add_settings
    from freecad_conformal.settings.mandrel import MAPPING

    add_settings(parser, (MAPPING,), groups={"mandrel": mandrel})


def add_plan_settings(parser: argparse.ArgumentParser) -> None:
    """Every plan setting (settings/plan.py) as a flag: shared by `plan` and `batch`."""
    from freecad_conformal.settings.cli import add_arguments as add_settings
    from freecad_conformal.settings.plan import PLAN_SETTINGS

    add_settings(parser, PLAN_SETTINGS)


def options_from(args: argparse.Namespace):
    """PlanOptions from the flags, checked by the settings schema (the Job object's path too)."""
    from freecad_conformal.jobs.options import plan_options
    from freecad_conformal.settings.cli import values_from_args
    from freecad_conformal.settings.plan import PLAN_SETTINGS

    return plan_options(values_from_args(args, PLAN_SETTINGS))


def plan_part(shape, name: str, options, output: str | Path, png: str | Path | None = None,
              summary: str | Path | None = None, toolpath: str | Path | None = None,
              report: str | Path | None = None):
    """Decompose (each solid standing on the platform, the part turned on the table when
    the machine cannot reach a sub-part as placed), plan and write (G-code, PNG, summary,
    toolpath); returns (result, written)."""
    from freecad_conformal.jobs.job import plan_job

    from freecad_conformal.fileio import guard_outputs

    png = png or Path(output).with_suffix(".png")
    guard_outputs([], {"-o/--output": output, "--png": png, "--summary": summary,
                       "--toolpath": toolpath, "--report": report})
    result = plan_job(shape, options, part=name)
    return result, result.write(output, png, summary, toolpath, report)


def run_mandrel(args: argparse.Namespace) -> int:
    """`plan --mandrel`: the same planner as the `mandrel` command."""
    from freecad_conformal.geometry.samples import load_part
    from freecad_conformal.jobs.mandrel import plan_mandrel

    options = options_from(args)
    shape, name = load_part(args.part)
    machine = "rotary_mandrel" if options.machine == "trunnion_ac" else options.machine
    result = plan_mandrel(shape, machine, options.tool, options.layers.thickness, args.output,
                          mapping=args.mapping or "rotary",
                          width=options.bead_width, part=name, toolpath_out=args.toolpath)
    print(result.report())
    print(f"wrote {args.output}", file=sys.stderr)
    return 0


def run(args: argparse.Namespace) -> int:
    from freecad_conformal.errors import PlanError
    from freecad_conformal.geometry.samples import load_part

    if args.mandrel:
        return run_mandrel(args)
    if args.mapping is not None:
        raise PlanError(f"--mapping {args.mapping} applies to mandrel builds only: add --mandrel")
    options = options_from(args)
    shape, name = load_part(args.part)
    result, written = plan_part(shape, name, options, args.output, args.png, args.summary,
                                args.toolpath, args.report)
    print(result.summary(), end="")
    print("wrote " + ", ".join(str(p) for p in written), file=sys.stderr)
    return 0
