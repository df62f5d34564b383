"""`stream PROGRAM.gcode --port PORT`: send a program to a machine, with a progress bar.

The job's state is saved beside the program (PROGRAM.gcode.stream.json unless --state or
--resume names it), so an interrupted job continues with `--resume STATEFILE`.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from freecad_conformal.settings.cli import add_arguments as add_settings
    from freecad_conformal.settings.stream import STREAM_SETTINGS

    parser.add_argument("program", help="G-code file to send")
    add_settings(parser, STREAM_SETTINGS)
    parser.add_argument("--resume", metavar="STATEFILE",
                        help="continue the job saved in STATEFILE after a disconnect or abort")
    parser.add_argument("--state", metavar="STATEFILE",
                        help="where to save the job's state (default PROGRAM.stream.json)")
    parser.add_argument("--from-line", type=int, metavar="N",
                        help="start at the first command at or after file line N (with "
                             "--resume: when the machine lost its place)")
    parser.add_argument("--log", metavar="FILE", help="append the serial traffic to FILE")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")


def run(args: argparse.Namespace) -> int:
    from freecad_conformal.progress import Progress
    from freecad_conformal.settings.cli import values_from_args
    from freecad_conformal.settings.schema import validate
    from freecad_conformal.settings.stream import STREAM_SETTINGS
    from freecad_conformal.stream import Streamer, load_program

    connection = validate(STREAM_SETTINGS, values_from_args(args, STREAM_SETTINGS))
    program = load_program(args.program)
    state_path = args.resume or args.state or f"{args.program}.stream.json"
    bar = Progress(len(program), label=Path(args.program).name)
    bar.enabled = bar.enabled and not args.quiet

    def show(progress) -> None:
        bar.update(progress.confirmed - bar.done)

    streamer = Streamer(program, connection["port"], protocol=connection["protocol"],
                        baud=connection["baud"],
                        state_path=state_path, log_path=args.log, resume=bool(args.resume),
                        from_line=args.from_line, on_progress=show)
    bar.update(streamer.state.confirmed)
    try:
        state = streamer.run()
    finally:
        bar.close()
        print(f"state saved to {state_path}", file=sys.stderr)
    print(f"{state.status}: {state.confirmed} of {state.total} commands acknowledged")
    return 0 if state.status == "done" else 1

