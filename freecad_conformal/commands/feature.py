"""`feature PART --face FaceN --kind rods|shell|pattern|channels -o out.npz [--gcode F]`:
conformal features on one face (METHODS section 1), tool along the surface normal (or
tilted by --tilt). Everything is planned (and post-processed when --gcode is given) before
any file is written: on an error nothing is written."""
from __future__ import annotations

import argparse
import sys

KINDS = ("rods", "shell", "pattern", "channels")


def _floats(text: str) -> list[float]:
    try:
        return [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected comma-separated numbers, got {text!r}") from None


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("part", help="STEP, BREP, IGES or FCStd file")
    parser.add_argument("--face", required=True, help="face name as FreeCAD shows it (Face1...)")
    parser.add_argument("--kind", required=True, choices=KINDS)
    parser.add_argument("-o", "--output", required=True, help="toolpath file to write (.npz)")
    parser.add_argument("--gcode", help="also post-process to this G-code file")
    parser.add_argument("--machine", default="head_a_table_c", help="machine for --gcode")
    parser.add_argument("--tool", help="tool id (default: uv_small for rods and pattern walls, "
                        "uv_large for shells; channels choose by curvature)")
    parser.add_argument("--tilt", type=float, default=0.0,
                        help="tilt of the tool from the surface normal, degrees (shell)")
    parser.add_argument("--feed", type=float, help="curing feed, mm/min (default: the tool's)")
    parser.add_argument("--layer", type=float, default=1.0, help="layer thickness, mm")
    parser.add_argument("--build-direction", type=_floats, default=[0.0, 0.0, 1.0],
                        help="direction tilts are measured from (default 0,0,1)")
    rods = parser.add_argument_group("rods")
    rods.add_argument("--spacing", type=float, default=3.0, help="rod spacing d on the surface, mm")
    rods.add_argument("--rod-length", type=float, default=3.0, help="rod height l, mm")
    rods.add_argument("--rod-diameter", type=float, default=1.2, help="rod diameter a, mm")
    rods.add_argument("--diameter-profile", type=_floats,
                      help="diameters along each rod, base to tip (varying speed)")
    rods.add_argument("--rings", type=int, help="rings N on a sphere (default: floor(W/θ))")
    shell = parser.add_argument_group("shell")
    shell.add_argument("--width", type=float, help="ring spacing / line width, mm")
    shell.add_argument("--layers", type=int, default=1, help="shell layers")
    shell.add_argument("--cup-height", type=float,
                       help="on a cone face: build an inverse conical cup wall this tall, mm")
    shell.add_argument("--first-layer", type=float, default=0.5, help="cup first layer, mm")
    pattern = parser.add_argument_group("pattern")
    pattern.add_argument("--svg", help="file holding one SVG path 'd' string (or an .svg file)")
    pattern.add_argument("--text", help="text to wrap onto the face")
    pattern.add_argument("--text-size", type=float, default=5.0, help="text size, mm")
    pattern.add_argument("--outline", help="BREP/STEP/FCStd whose closed XY wires are the outline")
    pattern.add_argument("--height", type=float, default=1.0, help="pattern height along the normal")
    pattern.add_argument("--fill", choices=("contours", "zigzag"), default="contours")
    pattern.add_argument("--at", type=_floats, help="face parameters u,v of the pattern centre")
    channels = parser.add_argument_group("channels")
    channels.add_argument("--channels", type=int, default=3, help="number of parallel channels")
    channels.add_argument("--channel-length", type=float, default=15.0)
    channels.add_argument("--gap", type=float, default=1.0, help="channel width, mm")
    channels.add_argument("--wall", type=float, default=1.0, help="wall width, mm")
    channels.add_argument("--wall-height", type=float, default=1.0)


def run(args: argparse.Namespace) -> int:
    from freecad_conformal.errors import ConformalError
    from freecad_conformal.geometry.faces import face_by_name
    from freecad_conformal.geometry.solids import load_shape

    shape = load_shape(args.part)
    what = f"{args.kind} on {args.face}"
    try:
        face = face_by_name(shape, args.face)
        toolpath = _plan(args, face, what)
        program = _post(args, toolpath) if args.gcode else None
    except ConformalError as exc:
        message = str(exc)
        raise type(exc)(message if message.startswith(what) else f"feature {what}: {message}") from None
    toolpath.save(args.output)
    if program is not None:
        from freecad_conformal.post.program import write_program
        write_program(args.gcode, program)
    summary = toolpath.summary()
    print(f"feature {what}: {summary.segments} segments, {summary.points} points, "
          f"cure path {summary.length_by_kind['cure']:.1f} mm, estimated {summary.time_s / 60:.1f} min")
    print(f"wrote {args.output}" + (f" and {args.gcode}" if args.gcode else ""), file=sys.stderr)
    return 0


def _post(args, toolpath):
    from freecad_conformal.post.machine import load_machine
    from freecad_conformal.post.program import post_toolpath
    return post_toolpath(toolpath, load_machine(args.machine))


def _tool(args, default: str):
    from freecad_conformal.process.library import ToolLibrary
    return ToolLibrary.load().get(args.tool or default)


def _feed(args, tool) -> float:
    if args.feed:
        return args.feed
    for settings in tool.settings.values():
        if settings.feed:
            return settings.feed
    return 24.0


def _plan(args, face, what):
    from freecad_conformal.paths.features import planners
    planner = {"rods": planners.plan_rods, "shell": planners.plan_shell,
               "pattern": planners.plan_pattern, "channels": planners.plan_channels}[args.kind]
    return planner(args, face, what, _tool, _feed)
