"""`sections PART --layer 0.2 [--direction 0,0,1] [--json out.json]`: a section report."""
from __future__ import annotations

import argparse
import json
import sys

from freecad_conformal.errors import ConformalError


def parse_vector(text: str) -> tuple[float, float, float]:
    try:
        values = tuple(float(part) for part in text.split(","))
    except ValueError:
        values = ()
    if len(values) != 3:
        raise argparse.ArgumentTypeError(f"expected three comma-separated numbers, got {text!r}")
    return values  # type: ignore[return-value]


def parse_heights(text: str) -> list[float]:
    try:
        return [float(part) for part in text.split(",") if part.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected comma-separated heights, got {text!r}") from None


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("part", help="STEP, BREP, IGES or FCStd file")
    group = parser.add_mutually_exclusive_group()
    group.add_argument("--layer", type=float, default=None,
                       help="uniform layer spacing in mm (default 1.0; planes at mid-layer)")
    group.add_argument("--heights", type=parse_heights, default=None,
                       help="explicit comma-separated heights (mm along the direction)")
    group.add_argument("--radii", type=parse_heights, default=None,
                       help="cylindrical sections at these comma-separated radii instead")
    parser.add_argument("--direction", type=parse_vector, default=(0.0, 0.0, 1.0),
                        help="build direction, or cylinder axis with --radii (default 0,0,1)")
    parser.add_argument("--axis-point", type=parse_vector, default=(0.0, 0.0, 0.0),
                        help="a point on the cylinder axis with --radii (default 0,0,0)")
    parser.add_argument("--chord", type=float, default=None,
                        help="chord tolerance of loop polygons in mm (default 0.001)")
    parser.add_argument("--workers", type=int, default=1, help="processes to use (default 1)")
    parser.add_argument("--json", metavar="FILE", help="write the documented JSON report here")


def run(args: argparse.Namespace) -> int:
    from freecad_conformal.geometry.report import section_report

    if args.workers < 1:
        raise ConformalError(f"--workers must be at least 1, got {args.workers}")
    report = section_report(
        args.part, layer=args.layer, heights=args.heights, radii=args.radii,
        direction=args.direction, axis_point=args.axis_point, chord=args.chord,
        workers=args.workers, json_path=args.json, show_progress=True)
    sys.stdout.write(report.table())
    if args.json:
        print(f"wrote {args.json}")
    return 0


def dumps(data: dict) -> str:
    return json.dumps(data, indent=1)
