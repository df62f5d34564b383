"""`post TOOLPATH --machine NAME [--dialect D] -o out.ngc`: toolpath -> G-code file."""
from __future__ import annotations

import argparse
import math
import sys


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from freecad_conformal.settings.cli import add_arguments as add_settings
    from freecad_conformal.settings.post import POST_SETTINGS

    parser.add_argument("toolpath", help="toolpath file (.npz written by Toolpath.save)")
    parser.add_argument("-o", "--output", required=True, help="G-code file to write")
    add_settings(parser, POST_SETTINGS)


def run(args: argparse.Namespace) -> int:
    from freecad_conformal.paths.timing import saved_toolpath_time
    from freecad_conformal.post.machine import load_machine
    from freecad_conformal.post.program import post_toolpath, write_program
    from freecad_conformal.settings.cli import values_from_args
    from freecad_conformal.settings.post import POST_SETTINGS
    from freecad_conformal.settings.schema import validate
    from freecad_conformal.toolpath import Toolpath

    v = validate(POST_SETTINGS, values_from_args(args, POST_SETTINGS))
    machine = load_machine(v["machine"])
    toolpath = Toolpath.load(args.toolpath)
    seconds = saved_toolpath_time(toolpath, machine)     # what the plan reported
    result = post_toolpath(toolpath, machine, v["dialect"], v["tolerance"],
                           math.radians(v["angular_tolerance"]), relative_e=not v["absolute_e"],
                           time_s=seconds)
    write_program(args.output, result)
    print(f"wrote {args.output}: {len(result.values)} blocks from {len(toolpath.points)} points, "
          f"estimated {result.time_s:.1f} s", file=sys.stderr)
    return 0
