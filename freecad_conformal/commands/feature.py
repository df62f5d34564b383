"""`feature PART --face FaceN --kind rods|shell|pattern|channels|texture -o out.npz
[--gcode F] [--preview F.png]`: conformal features on one face (METHODS section 1), tool
along the surface normal (or tilted by --tilt). Everything is planned (and post-processed
when --gcode is given) before any file is written: on an error nothing is written. A
preview PNG is written next to the toolpath (OUTPUT with .png) unless --preview says where."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from freecad_conformal.settings.cli import add_arguments as add_settings
    from freecad_conformal.settings.feature import FEATURE_SETTINGS, KINDS

    parser.add_argument("part", help="STEP, BREP, IGES or FCStd file")
    parser.add_argument("--face", required=True, help="face name as FreeCAD shows it (Face1...)")
    parser.add_argument("--kind", required=True, choices=KINDS)
    parser.add_argument("-o", "--output", required=True, help="toolpath file to write (.npz)")
    parser.add_argument("--gcode", help="also post-process to this G-code file")
    parser.add_argument("--machine", default="head_a_table_c", help="machine for --gcode")
    parser.add_argument("--preview", help="preview PNG (default: the output with .png)")
    add_settings(parser, FEATURE_SETTINGS)


def run(args: argparse.Namespace) -> int:
    from freecad_conformal.errors import ConformalError
    from freecad_conformal.geometry.faces import face_by_name
    from freecad_conformal.geometry.solids import load_shape

    shape = load_shape(args.part)
    what = f"{args.kind} on {args.face}"
    try:
        face = face_by_name(shape, args.face)
        toolpath = _plan(args, face, what, shape)
        program = _post(args, toolpath) if args.gcode else None
    except ConformalError as exc:
        message = str(exc)
        raise type(exc)(message if message.startswith(what) else f"feature {what}: {message}") from None
    toolpath.save(args.output)
    if program is not None:
        from freecad_conformal.post.program import write_program
        write_program(args.gcode, program)
    preview = args.preview or str(Path(args.output).with_suffix(".png"))
    from freecad_conformal.paths.features.preview import write_preview
    write_preview(toolpath, preview, f"{args.kind} on {Path(args.part).name} {args.face}",
                  _surface(face))
    summary = toolpath.summary()
    print(f"feature {what}: {summary.segments} segments, {summary.points} points, "
          f"cure path {summary.length_by_kind['cure']:.1f} mm, {summary.energy:.3f} J cured, "
          f"estimated {summary.time_s / 60:.1f} min")
    for key in ("tools", "tool_choice", "process"):
        if toolpath.metadata.get(key):
            print(f"  {key.replace('_', ' ')}: {toolpath.metadata[key]}")
    print(f"wrote {args.output}, {preview}" + (f" and {args.gcode}" if args.gcode else ""),
          file=sys.stderr)
    return 0


def _surface(face):
    from freecad_conformal.paths.features.clearance import part_samples
    return part_samples(face, 1.0)


def _post(args, toolpath):
    from freecad_conformal.post.machine import load_machine
    from freecad_conformal.post.program import post_toolpath
    return post_toolpath(toolpath, load_machine(args.machine))


def _plan(args, face, what, part):
    from freecad_conformal.jobs.feature import plan_feature
    from freecad_conformal.settings.cli import values_from_args
    from freecad_conformal.settings.feature import FEATURE_SETTINGS

    return plan_feature(face, args.kind, values_from_args(args, FEATURE_SETTINGS), what, part=part)
