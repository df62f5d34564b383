"""`plan PART --machine NAME --tool ID [--layer 0.2] -o out.gcode`: the project's main job.

PART is a STEP/BREP/IGES/FCStd file or the name of a built-in sample part (bracket, jack).
Prints the summary, writes the G-code, a PNG preview (paths coloured by sub-part) and,
on request, the summary and the neutral toolpath.
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("part", help="part file (STEP, BREP, IGES, FCStd) or a built-in sample name")
    parser.add_argument("-o", "--output", required=True, help="G-code file to write")
    parser.add_argument("--png", help="preview image (default: the output with .png)")
    parser.add_argument("--summary", help="also write the summary to this text file")
    parser.add_argument("--toolpath", help="also save the neutral toolpath (.npz)")
    add_plan_settings(parser)
    mandrel = parser.add_argument_group("rotating mandrel (METHODS section 5)")
    mandrel.add_argument("--mandrel", action="store_true",
                         help="build around the machine's rotary mandrel in unrolled cylindrical layers "
                              "(machine default rotary_mandrel)")
    mandrel.add_argument("--mapping", choices=("rotary", "linear"), default="rotary",
                         help="with --mandrel: A in degrees, or the rotation as a linear axis at R0")


def add_plan_settings(parser: argparse.ArgumentParser) -> None:
    """Machine, tool, layer and path settings: shared by `plan` and `batch`."""
    parser.add_argument("--machine", default="trunnion_ac",
                        help="machine name or .json path (default trunnion_ac)")
    parser.add_argument("--tool", default="fdm_0p4", help="tool id in the library (default fdm_0p4)")
    parser.add_argument("--material", help="material of the tool's settings (default: its first)")
    parser.add_argument("--dialect", help="G-code dialect (default: the machine's)")
    parser.add_argument("--root", default="auto",
                        help="build direction of each solid's first sub-part: auto (as placed "
                             "unless turning the solid leaves less overhang; default) or x,y,z")
    layers = parser.add_argument_group("layers")
    layers.add_argument("--layer", type=float, default=0.2, help="layer height in mm (default 0.2)")
    layers.add_argument("--layer-mode", choices=("uniform", "adaptive", "cusp"), default="uniform")
    layers.add_argument("--layer-min", type=float, help="minimum layer height (default 0.5 x --layer)")
    layers.add_argument("--layer-max", type=float, help="maximum layer height (default 1.5 x --layer)")
    layers.add_argument("--max-volume-difference", type=float, default=2.0,
                        help="adaptive limit per layer in mm3 (default 2)")
    layers.add_argument("--max-cusp", type=float, default=0.05, help="cusp height limit in mm")
    layers.add_argument("--tilt", action=argparse.BooleanOptionalAction, default=True,
                        help="3-D layers: tilt the planes where a sub-part's centroidal axis bends "
                             "(default on; --no-tilt keeps every layer planar)")
    paths = parser.add_argument_group("paths")
    paths.add_argument("--bead-width", type=float, help="bead width in mm (default: the material's)")
    paths.add_argument("--perimeters", type=int, default=2)
    paths.add_argument("--infill", type=float, default=20.0, help="sparse infill in percent (default 20)")
    paths.add_argument("--infill-angle", type=float, help="infill angle in degrees (default: fewest turns)")
    paths.add_argument("--seam", choices=("aligned", "nearest", "sharpest"), default="aligned")
    paths.add_argument("--solid-layers", type=int, default=3, help="top and bottom solid layers (default 3)")
    paths.add_argument("--bead-model", choices=("rounded", "rectangular"), default="rounded",
                       help="bead cross-section: rounded sides (PrusaSlicer's, default) or a rectangle")
    paths.add_argument("--infill-overlap", type=float, default=25.0,
                       help="infill reach into the innermost perimeter, percent of a bead spacing (default 25)")
    paths.add_argument("--solid-below-area", type=float, default=70.0,
                       help="sparse infill pieces smaller than this (mm2) are printed solid (default 70)")


def load_part(name: str):
    """A part file, or a built-in sample when no such file exists and the name is a sample."""
    from freecad_conformal.geometry import samples
    from freecad_conformal.geometry.solids import load_shape

    if not Path(name).exists() and name in samples.SAMPLES:
        return samples.SAMPLES[name](), name
    return load_shape(name), Path(name).stem


def options_from(args: argparse.Namespace):
    from freecad_conformal.errors import PlanError
    from freecad_conformal.paths.assemble import PathSettings
    from freecad_conformal.paths.fill2d import FillSettings
    from freecad_conformal.jobs.plan import PlanOptions
    from freecad_conformal.layers.model import LayerSettings

    if not 0.0 <= args.infill <= 100.0:
        raise PlanError(f"--infill {args.infill:g} must be a percentage 0..100")
    if not 0.0 <= args.infill_overlap < 100.0:
        raise PlanError(f"--infill-overlap {args.infill_overlap:g} must be a percentage 0..100")
    angle = None if args.infill_angle is None else math.radians(args.infill_angle)
    fill = FillSettings(bead_width=args.bead_width or 0.4, perimeters=args.perimeters,
                        density=args.infill / 100.0, angle=angle, seam=args.seam,
                        bead_model=args.bead_model, infill_overlap=args.infill_overlap / 100.0,
                        solid_below_area=args.solid_below_area)
    layers = LayerSettings(mode=args.layer_mode, thickness=args.layer, min_thickness=args.layer_min,
                           max_thickness=args.layer_max, max_volume_difference=args.max_volume_difference,
                           max_cusp=args.max_cusp, tilt=args.tilt)
    paths = PathSettings(fill=fill, top_layers=args.solid_layers, bottom_layers=args.solid_layers)
    return PlanOptions(machine=args.machine, tool=args.tool, material=args.material, layers=layers,
                       paths=paths, bead_width=args.bead_width, dialect=args.dialect,
                       root=root_option(args.root))


def root_option(text: str):
    """`--root`: "auto" or a direction "x,y,z"."""
    from freecad_conformal.errors import PlanError

    if text == "auto":
        return text
    try:
        vector = tuple(float(c) for c in text.split(","))
    except ValueError:
        vector = ()
    if len(vector) != 3:
        raise PlanError(f"--root must be auto or a direction x,y,z, got {text!r}")
    return vector


def plan_part(shape, name: str, options, output: str | Path, png: str | Path | None = None,
              summary: str | Path | None = None, toolpath: str | Path | None = None):
    """Decompose (each solid standing on the platform, the part turned on the table when
    the machine cannot reach a sub-part as placed), plan and write (G-code, PNG, summary,
    toolpath); returns (result, written)."""
    from freecad_conformal.jobs.plan import check_options, machine_plan, run_job

    check_options(shape, options)
    shape, plan = machine_plan(shape, options)
    result = run_job(shape, plan, options, part=name)
    png = png or Path(output).with_suffix(".png")
    written = result.write(output, png, summary)
    if toolpath:
        result.assembly.toolpath.save(toolpath)
        written.append(Path(toolpath))
    return result, written


def run_mandrel(args: argparse.Namespace) -> int:
    """`plan --mandrel`: the same planner as the `mandrel` command."""
    from freecad_conformal.jobs.mandrel import plan_mandrel

    shape, name = load_part(args.part)
    machine = "rotary_mandrel" if args.machine == "trunnion_ac" else args.machine
    result = plan_mandrel(shape, machine, args.tool, args.layer, args.output, mapping=args.mapping,
                          width=args.bead_width, part=name, toolpath_out=args.toolpath)
    print(result.report())
    print(f"wrote {args.output}", file=sys.stderr)
    return 0


def run(args: argparse.Namespace) -> int:
    if args.mandrel:
        return run_mandrel(args)
    options = options_from(args)
    shape, name = load_part(args.part)
    result, written = plan_part(shape, name, options, args.output, args.png, args.summary,
                                args.toolpath)
    print(result.summary(), end="")
    print("wrote " + ", ".join(str(p) for p in written), file=sys.stderr)
    return 0
