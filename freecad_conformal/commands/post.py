"""`post TOOLPATH --machine NAME [--dialect D] -o out.ngc`: toolpath -> G-code file."""
from __future__ import annotations

import argparse
import math
import sys


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("toolpath", help="toolpath file (.npz written by Toolpath.save)")
    parser.add_argument("--machine", required=True,
                        help="machine name (file stem in resources/machines) or path to a .json")
    parser.add_argument("--dialect", help="G-code dialect (default: the machine's): "
                        "linuxcnc, marlin, reprap, grblhal")
    parser.add_argument("-o", "--output", required=True, help="G-code file to write")
    parser.add_argument("--tolerance", type=float, default=None,
                        help="tool-tip tolerance in mm (default 0.01)")
    parser.add_argument("--angular-tolerance", type=float, default=None,
                        help="tool-axis tolerance in degrees (default 0.05)")
    parser.add_argument("--absolute-e", action="store_true",
                        help="absolute extrusion (M82) instead of relative (M83)")


def run(args: argparse.Namespace) -> int:
    from freecad_conformal.post.machine import load_machine
    from freecad_conformal.post.program import post_toolpath, write_program
    from freecad_conformal.tolerances import DEFAULT_ANGULAR_TOLERANCE, DEFAULT_LINEAR_TOLERANCE
    from freecad_conformal.toolpath import Toolpath

    machine = load_machine(args.machine)
    toolpath = Toolpath.load(args.toolpath)
    tolerance = DEFAULT_LINEAR_TOLERANCE if args.tolerance is None else args.tolerance
    angular = (DEFAULT_ANGULAR_TOLERANCE if args.angular_tolerance is None
               else math.radians(args.angular_tolerance))
    result = post_toolpath(toolpath, machine, args.dialect, tolerance, angular,
                           relative_e=not args.absolute_e)
    write_program(args.output, result)
    print(f"wrote {args.output}: {len(result.values)} blocks from {len(toolpath.points)} points, "
          f"estimated {result.time_s:.1f} s", file=sys.stderr)
    return 0
