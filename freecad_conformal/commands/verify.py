"""`verify PROGRAM --machine NAME --toolpath TOOLPATH`: replay G-code through forward
kinematics and report the largest deviation from the designed toolpath."""
from __future__ import annotations

import argparse
import math


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("program", help="G-code file written by `post`")
    parser.add_argument("--machine", required=True,
                        help="machine name (file stem in resources/machines) or path to a .json")
    parser.add_argument("--toolpath", required=True, help="the designed toolpath (.npz)")
    parser.add_argument("--max-position", type=float, default=None,
                        help="exit 1 if the position deviation exceeds this (mm)")
    parser.add_argument("--max-angle", type=float, default=None,
                        help="exit 1 if the angle deviation exceeds this (degrees)")


def run(args: argparse.Namespace) -> int:
    from freecad_conformal.post.machine import load_machine
    from freecad_conformal.post.verify import verify_file
    from freecad_conformal.toolpath import Toolpath

    machine = load_machine(args.machine)
    toolpath = Toolpath.load(args.toolpath)
    deviation = verify_file(args.program, machine, toolpath)
    print(deviation.report())
    too_far = args.max_position is not None and deviation.position > args.max_position
    too_bent = args.max_angle is not None and math.degrees(deviation.angle) > args.max_angle
    return 1 if too_far or too_bent else 0
