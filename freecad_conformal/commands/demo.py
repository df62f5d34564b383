"""`demo --out DIR`: the main job on the built-in sample part (the README's first command).

Writes the sample as STEP, its section report, and the plan: G-code for the default
machine and tool, a PNG preview coloured by sub-part and the plan summary.
"""
from __future__ import annotations

import argparse


def demo_settings() -> list:
    """The plan's and the section report's own settings under the demo's flags."""
    from dataclasses import replace

    from freecad_conformal.settings.plan import PLAN_SETTINGS
    from freecad_conformal.settings.sections import SECTIONS_SETTINGS

    def setting(settings, name: str, **changes):
        found = next(s for s in settings if s.key == name)
        return replace(found, group="demo", prop="", aliases=(), only_when=None, **changes)

    return [setting(SECTIONS_SETTINGS, "layer", key="section_layer", flag="--layer",
                    label="section spacing",
                    help="layer spacing of the section report"),
            setting(PLAN_SETTINGS, "layer_height", flag="--plan-layer",
                    help="layer height of the plan"),
            setting(PLAN_SETTINGS, "machine"), setting(PLAN_SETTINGS, "tool")]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from freecad_conformal.settings.cli import add_arguments as add_settings

    parser.add_argument("--out", default="out", help="output folder (default out/)")
    parser.add_argument("--sample", default="bracket", help="built-in sample part (bracket, jack, ...)")
    add_settings(parser, demo_settings())


def run(args: argparse.Namespace) -> int:
    from freecad_conformal.commands.plan import plan_part
    from freecad_conformal.errors import ConformalError
    from freecad_conformal.fileio import make_output_folder
    from freecad_conformal.geometry import samples
    from freecad_conformal.geometry.report import section_report
    from freecad_conformal.jobs.options import plan_options
    from freecad_conformal.jobs.plan import check_options
    from freecad_conformal.settings.cli import values_from_args
    from freecad_conformal.settings.schema import validate

    if args.sample not in samples.SAMPLES:
        raise ConformalError(f"unknown sample {args.sample!r}; choose from {', '.join(samples.SAMPLES)}")
    settings = demo_settings()
    values = validate(settings, values_from_args(args, settings))
    section_layer = values.pop("section_layer")
    options = plan_options(values)
    shape = samples.SAMPLES[args.sample]()
    check_options(shape, options)          # a bad machine or tool writes nothing
    out = make_output_folder(args.out)
    step_path = out / f"{args.sample}.step"
    shape.exportStep(str(step_path))
    json_path = out / f"{args.sample}_sections.json"
    report = section_report(shape, layer=section_layer, json_path=json_path, show_progress=True)
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
