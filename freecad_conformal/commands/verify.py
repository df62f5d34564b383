"""`verify PROGRAM --machine NAME --toolpath TOOLPATH`: replay G-code through forward
kinematics and report the largest deviation from the designed toolpath."""
from __future__ import annotations

import argparse
import math


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from freecad_conformal.settings.cli import add_arguments as add_settings
    from freecad_conformal.settings.post import VERIFY_SETTINGS

    parser.add_argument("program", help="G-code file written by `post`")
    parser.add_argument("--toolpath", required=True, help="the designed toolpath (.npz)")
    add_settings(parser, VERIFY_SETTINGS)


def run(args: argparse.Namespace) -> int:
    from freecad_conformal.post.machine import load_machine
    from freecad_conformal.post.verify import verify_file
    from freecad_conformal.settings.cli import values_from_args
    from freecad_conformal.settings.post import VERIFY_SETTINGS
    from freecad_conformal.settings.schema import validate
    from freecad_conformal.toolpath import Toolpath

    v = validate(VERIFY_SETTINGS, values_from_args(args, VERIFY_SETTINGS))
    machine = load_machine(v["machine"])
    toolpath = Toolpath.load(args.toolpath)
    deviation = verify_file(args.program, machine, toolpath)
    print(deviation.report())
    too_far = deviation.position > v["max_position"]
    too_bent = math.degrees(deviation.angle) > v["max_angle"]
    return 1 if too_far or too_bent else 0
