"""`tools list|show|check|import|export|choose`: the tool library from the command line."""
from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

from freecad_conformal.errors import ConformalError

from freecad_conformal.errors import ProcessError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--user-dir", type=Path, default=None,
                        help="user tool folder (default: FreeCAD's user data folder/Conformal/"
                             "tools, or $CONFORMAL_USER_DIR/tools)")
    sub = parser.add_subparsers(dest="tools_command", metavar="ACTION")
    sub.required = True
    sub.add_parser("list", help="list the tools (shipped defaults and user tools)")
    show = sub.add_parser("show", help="show one tool")
    show.add_argument("tool_id")
    show.add_argument("--json", action="store_true", help="print the tool's JSON")
    check = sub.add_parser("check", help="check tool files (default: the whole library)")
    check.add_argument("files", nargs="*", type=Path)
    imp = sub.add_parser("import", help="add the tools of a file to the user library")
    imp.add_argument("file", type=Path)
    imp.add_argument("--replace", action="store_true", help="replace tools with the same id")
    exp = sub.add_parser("export", help="write tools into one file")
    exp.add_argument("out", type=Path, help="file to write (.json)")
    exp.add_argument("tool_ids", nargs="*", help="tools to export (default: all)")
    choose = sub.add_parser("choose", help="tools that fit a curvature (METHODS section 1)")
    choose.add_argument("--rs", type=float, required=True,
                        help="smallest radius of curvature of the face (mm; inf for flat)")
    choose.add_argument("--cd", type=float, required=True, help="curing depth (mm)")
    choose.add_argument("--theta", type=float, required=True, help="rotation θ (degrees)")
    choose.add_argument("--resolution", type=float, default=None,
                        help="finest feature width needed (mm)")
    choose.add_argument("--all-kinds", action="store_true",
                        help="consider every tool kind, not only UV light guides")


def run(args: argparse.Namespace) -> int:
    from freecad_conformal.process.library import ToolLibrary, read_tool_file, user_tool_dir

    user_dir = args.user_dir if args.user_dir is not None else user_tool_dir()
    if args.tools_command == "check" and args.files:
        return _check_files(args.files, read_tool_file)
    library = ToolLibrary.load(user_dir=user_dir)
    if args.tools_command == "list":
        print(f"{'id':<20} {'kind':<15} {'dt mm':>6} {'head':<12} {'W°':>5}  origin   name")
        for tool in library:
            head = (f"angled {math.degrees(tool.bend_angle):g}°" if tool.head == "angled"
                    else "straight")
            print(f"{tool.id:<20} {tool.kind:<15} {tool.diameter:>6g} {head:<12} "
                  f"{math.degrees(tool.max_tilt):>5.0f}  {library.origin(tool.id):<8} {tool.name}")
        print(f"{len(library)} tools; user folder {user_dir}")
    elif args.tools_command == "show":
        tool = library.get(args.tool_id)
        if args.json:
            print(json.dumps(tool.to_dict(), indent=2))
        else:
            _print_tool(tool, library.origin(tool.id))
    elif args.tools_command == "check":
        print(f"ok: {len(library)} tools (defaults and {user_dir}) passed the schema check")
    elif args.tools_command == "import":
        added = library.import_file(args.file, replace=args.replace)
        library.save()
        print(f"imported {', '.join(added)} into {user_dir}")
    elif args.tools_command == "export":
        if args.out.suffix.lower() != ".json":
            # `tools export uv_small` would write every tool into a file named uv_small
            hint = (f"; to export tool {args.out.name}: tools export FILE.json {args.out.name}"
                    if str(args.out) in {t.id for t in library} else "")
            raise ConformalError(f"export file {args.out} must end in .json{hint}")
        library.export(args.out, args.tool_ids or None)
        print(f"wrote {len(args.tool_ids) or len(library)} tools to {args.out}")
    elif args.tools_command == "choose":
        from freecad_conformal.process.selection import choose_tool

        choice = choose_tool(library, args.rs, args.cd, math.radians(args.theta),
                             args.resolution, kind=None if args.all_kinds else "uv_light_guide")
        print(choice.explanation())
        return 0 if choice.recommended is not None else 1
    return 0


def _check_files(files: list[Path], read_tool_file) -> int:
    failures = 0
    for path in files:
        try:
            tools = read_tool_file(path)
        except ProcessError as exc:
            failures += 1
            print(f"FAIL {path}: {exc}")
        else:
            print(f"ok   {path}: {', '.join(t.id for t in tools)}")
    return 1 if failures else 0


def _print_tool(tool, origin: str) -> None:
    print(f"{tool.id}: {tool.name} ({tool.kind}, {origin})")
    print(f"  diameter dt {tool.diameter:g} mm, head {tool.head}"
          + (f" bent {math.degrees(tool.bend_angle):g}°" if tool.head == "angled" else "")
          + f", max tilt W {math.degrees(tool.max_tilt):g}°")
    env = tool.envelope
    print(f"  envelope: cone {env.tip_diameter:g} -> {env.body_diameter:g} mm over "
          f"{env.tip_length:g} mm, body {env.body_length:g} mm")
    for key, value in tool.spec.to_dict().items():
        print(f"  {key}: {value}")
    for material, settings in tool.settings.items():
        print(f"  settings for {material}: {json.dumps(settings.to_dict())}")
    if tool.notes:
        print(f"  notes: {tool.notes}")
