"""`demo --out DIR`: the main job on the built-in sample part (the README's first command)."""
from __future__ import annotations

import argparse
from pathlib import Path


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--out", default="out", help="output folder (default out/)")
    parser.add_argument("--sample", default="bracket", help="built-in sample part (bracket, jack)")
    parser.add_argument("--layer", type=float, default=1.0, help="layer spacing in mm")


def run(args: argparse.Namespace) -> int:
    from freecad_conformal.errors import ConformalError
    from freecad_conformal.geometry import samples
    from freecad_conformal.geometry.report import section_report

    if args.sample not in samples.SAMPLES:
        raise ConformalError(f"unknown sample {args.sample!r}; choose from {', '.join(samples.SAMPLES)}")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    shape = samples.SAMPLES[args.sample]()
    step_path = out / f"{args.sample}.step"
    shape.exportStep(str(step_path))
    json_path = out / f"{args.sample}_sections.json"
    report = section_report(shape, layer=args.layer, json_path=json_path, show_progress=True)
    report.source = step_path.name
    table = report.table()
    (out / f"{args.sample}_sections.txt").write_text(table, encoding="utf-8")
    print(table, end="")
    print(f"wrote {step_path}, {json_path} and {out / (args.sample + '_sections.txt')}")
    return 0
