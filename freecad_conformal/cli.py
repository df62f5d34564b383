"""`python -m freecad_conformal COMMAND ...`: the headless entry point.

Each command lives in `freecad_conformal/commands/<name>.py` and exposes
`add_arguments(parser)` and `run(args) -> int`. Those modules import heavy dependencies
(FreeCAD, matplotlib) inside `run`, so `--help` is instant and pure commands never load
FreeCAD.
"""
from __future__ import annotations

import argparse
import atexit
import importlib
import logging
import math
import os
import sys
import threading
from typing import NoReturn, Sequence

from freecad_conformal import __version__
from freecad_conformal.errors import ConformalError

#: command name -> (module under freecad_conformal.commands, one-line help)
COMMANDS: dict[str, tuple[str, str]] = {
    "demo": ("demo", "the main job on a built-in sample part, written to out/"),
    "sections": ("sections", "exact planar or cylindrical sections of a solid"),
    "decompose": ("decompose", "split a part into support-free sub-parts and order them"),
    "post": ("post", "post-process a toolpath into G-code for a machine"),
    "verify": ("verify", "replay G-code through kinematics against the toolpath"),
    "doe": ("doe", "design of experiments: run sheets, effects, models, optimum"),
    "tools": ("tools", "tool library: list, show, check, import, export, choose"),
    "stream": ("stream", "send G-code to a machine over a serial port (Marlin or grbl), resumably"),
    "mandrel": ("mandrel", "build around a rotating mandrel: unrolled cylindrical layers to G-code"),
    "feature": ("feature", "conformal features on a face: rods, shells, patterns, channels"),
    "plan": ("plan", "the main job: support-free multi-axis build plan and 5-axis G-code for a part"),
    "batch": ("batch", "plan and post many parts (files, globs, FCStd bodies) on local or Dask workers"),
}


#: Per command, the arguments that name files it reads and files it writes: an output must
#: never replace an input or another output, and its folder must exist (fileio.guard_outputs).
FILE_ARGUMENTS: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {
    "plan": (("part",), ("output", "png", "summary", "toolpath", "report")),
    "feature": (("part", "svg", "outline"), ("output", "gcode")),
    "mandrel": (("part",), ("output", "toolpath")),
    "post": (("toolpath",), ("output",)),
    "sections": (("part",), ("json",)),
    "decompose": (("part",), ("json",)),
    "stream": (("program",), ("state", "log")),
}


def guard_files(args: argparse.Namespace) -> None:
    """Refuse, before any work, outputs that would overwrite an input or cannot be written."""
    from freecad_conformal.fileio import guard_outputs

    inputs, outputs = FILE_ARGUMENTS.get(args.command, ((), ()))
    named = {f"--{name}" if name != "output" else "-o/--output": getattr(args, name, None)
             for name in outputs}
    paths = {name: value for name, value in named.items() if isinstance(value, (str, os.PathLike))}
    guard_outputs([getattr(args, name, None) for name in inputs
                   if isinstance(getattr(args, name, None), (str, os.PathLike))], paths)


#: What every command's help ends with: how its numbers are read (settings/cli.py).
QUANTITIES_EPILOG = ("A number is in the unit its flag's help names (mm, deg, mm/s, s, ...); "
                     "it may carry a unit of its own instead: --layer-height 200um, "
                     "--infill-angle 0.8rad, --travel-speed 7.8m/min. Percentages may end in %.")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m freecad_conformal",
        description="Conformal: multi-axis additive process planning on exact B-rep solids.",
    )
    parser.add_argument("--version", action="version", version=f"conformal {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for name, (module_name, help_text) in COMMANDS.items():
        module = importlib.import_module(f"freecad_conformal.commands.{module_name}")
        command_parser = sub.add_parser(name, help=help_text, description=help_text,
                                        epilog=QUANTITIES_EPILOG)
        module.add_arguments(command_parser)
        command_parser.set_defaults(_run=module.run)
    return parser


class WarningPrinter(logging.Handler):
    """Prints the package's warnings (repaired or skipped input) as `warning: ...` lines on the
    stderr of the moment (so redirections made after start-up are honoured)."""

    def __init__(self) -> None:
        super().__init__(logging.WARNING)

    def emit(self, record: logging.LogRecord) -> None:
        print(f"warning: {record.getMessage()}", file=sys.stderr)


#: Environment variable: seconds a part file may spend in FreeCAD's reader (0: no limit).
READ_LIMIT_VARIABLE = "CONFORMAL_READ_TIME_LIMIT"
#: Default of that limit: far above any real file's read (a 200 MB STEP reads in minutes).
DEFAULT_READ_LIMIT_S = 900.0


def enable_reading_watchdog() -> None:
    """For `python -m freecad_conformal` only (a process of its own): a part file that keeps
    FreeCAD's reader busy past the limit ends the command with an error naming the file."""
    from freecad_conformal.geometry import solids

    text = os.environ.get(READ_LIMIT_VARIABLE, "")
    try:
        limit = float(text) if text else DEFAULT_READ_LIMIT_S
    except ValueError:
        limit = DEFAULT_READ_LIMIT_S
    solids.READ_TIME_LIMIT[0] = limit if limit > 0 and math.isfinite(limit) else None


def leave(code: int) -> NoReturn:
    """End `python -m freecad_conformal` with `code`, skipping the interpreter's teardown:
    FreeCAD's and OCC's destructors and every module's took 35 ms of a 0.5 s plan of
    wedge_ok on FreeCAD 0.20 and 45-55 ms of 0.65 s on 1.0, and nothing in them is ours.
    What must happen at exit still does: the handlers registered with `atexit` (logging's
    flush, multiprocessing's, a Dask client's) run, and the output streams are flushed.
    Where a thread that is not a daemon still runs (the interpreter would wait for it) or
    `atexit` cannot be run by hand, the ordinary exit is taken."""
    run_handlers = getattr(atexit, "_run_exitfuncs", None)
    if run_handlers is None or any(thread is not threading.main_thread() and not thread.daemon
                                   and thread.is_alive() for thread in threading.enumerate()):
        sys.exit(code)
    run_handlers()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            pass    # a reader that went away (`plan ... | head`) or a closed stream
    os._exit(code)


def main(argv: Sequence[str] | None = None) -> int:
    """Run one command; return its exit code (2 for usage errors, 1 for failures)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    log = logging.getLogger("freecad_conformal")
    if not any(isinstance(h, WarningPrinter) for h in log.handlers):
        log.addHandler(WarningPrinter())
    try:
        guard_files(args)
        return int(args._run(args) or 0)
    except ConformalError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt as exc:
        print(f"interrupted{': ' + str(exc) if str(exc) else ''}", file=sys.stderr)
        return 130
