"""`demo --out DIR`: the main job on the built-in sample part (the README's first command).

Writes the sample as STEP, its section report, and the plan: G-code for the default
machine and tool, a PNG preview coloured by sub-part and the plan summary.
"""
from __future__ import annotations

import argparse


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--out", default="out", help="output folder (default out/)")
    parser.add_argument("--sample", default="bracket", help="built-in sample part (bracket, jack, ...)")
    parser.add_argument("--layer", type=float, default=1.0, help="section report spacing in mm")
    parser.add_argument("--plan-layer", type=float, default=0.2, help="plan layer height in mm")
    parser.add_argument("--machine", default="trunnion_ac", help="machine of the plan")
    parser.add_argument("--tool", default="fdm_0p4", help="tool of the plan")


def run(args: argparse.Namespace) -> int:
    from freecad_conformal.commands.plan import plan_part
    from freecad_conformal.errors import ConformalError
    from freecad_conformal.fileio import make_output_folder
    from freecad_conformal.geometry import samples
    from freecad_conformal.geometry.report import section_report
    from freecad_conformal.jobs.options import plan_options
    from freecad_conformal.jobs.plan import check_options

    if args.sample not in samples.SAMPLES:
        raise ConformalError(f"unknown sample {args.sample!r}; choose from {', '.join(samples.SAMPLES)}")
    options = plan_options({"machine": args.machine, "tool": args.tool,
                            "layer_height": args.plan_layer})
    shape = samples.SAMPLES[args.sample]()
    check_options(shape, options)          # a bad machine or tool writes nothing
    out = make_output_folder(args.out)
    step_path = out / f"{args.sample}.step"
    shape.exportStep(str(step_path))
    json_path = out / f"{args.sample}_sections.json"
    report = section_report(shape, layer=args.layer, json_path=json_path, show_progress=True)
    report.source = step_path.name
    table = report.table()
    (out / f"{args.sample}_sections.txt").write_text(table, encoding="utf-8")
    print(table, end="")
    result, written = plan_part(shape, args.sample, options, out / f"{args.sample}.ngc",
                                out / f"{args.sample}_plan.png", out / f"{args.sample}_plan.txt")
    print()
    print(result.summary(), end="")
    files = [step_path, json_path, out / f"{args.sample}_sections.txt", *written]
    print("wrote " + ", ".join(str(f) for f in files))
    return 0
