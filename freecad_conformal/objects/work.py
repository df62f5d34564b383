"""The objects' computations on plain data, and the worker process that runs them.

`compute(task, inputs)` is what an object's recompute calls in-process; the GUI runs the
same call in a separate Python (`python -m freecad_conformal.objects.work IN OUT`), so the
GUI thread stays free and Cancel can end the work at once. The worker reads a pickle of
(task, inputs), prints progress lines on stdout and writes {"result": ...} or {"error":
one line, "kind": the error class, "traceback": ...} to OUT. Nothing here opens a document.
"""
from __future__ import annotations

import importlib
import pickle
import sys
import traceback
from typing import Any, Callable

#: task -> "module:function"; each function takes (inputs, progress) and returns plain data.
TASKS = {
    "job": "freecad_conformal.objects.job_feature:compute_job",
    "decomposition": "freecad_conformal.objects.analysis_compute:compute_decomposition",
    "analysis": "freecad_conformal.objects.analysis_compute:compute_analysis",
    "sections": "freecad_conformal.objects.sections_feature:compute_sections",
    "post": "freecad_conformal.objects.post_feature:compute_post",
    "verify": "freecad_conformal.objects.post_feature:compute_verify",
    "feature": "freecad_conformal.objects.feature_object:compute_feature",
}
#: How a progress line starts on the worker's stdout: PREFIX, fraction (or -), text.
PROGRESS_PREFIX = "conformal-progress"

Progress = Callable[[float | None, str], None]


def no_progress(_fraction: float | None, _text: str) -> None:
    return None


def compute(task: str, inputs: dict, progress: Progress = no_progress) -> dict:
    """The result of `task` on plain `inputs` (raises the ConformalError of the failure)."""
    if task not in TASKS:
        raise KeyError(f"unknown task {task!r}; known: {', '.join(TASKS)}")
    module, function = TASKS[task].split(":")
    return getattr(importlib.import_module(module), function)(inputs, progress)


def print_progress(fraction: float | None, text: str) -> None:
    """A progress line on stdout (the GUI reads the last one)."""
    share = "-" if fraction is None else f"{max(0.0, min(1.0, fraction)):.3f}"
    print(f"{PROGRESS_PREFIX}\t{share}\t{text}", flush=True)


def parse_progress(line: str) -> tuple[float | None, str] | None:
    """(fraction or None, text) of a progress line; None for any other line."""
    parts = line.rstrip("\n").split("\t", 2)
    if len(parts) != 3 or parts[0] != PROGRESS_PREFIX:
        return None
    return (None if parts[1] == "-" else float(parts[1])), parts[2]


def outcome_of(task: str, inputs: dict, progress: Progress = no_progress) -> dict[str, Any]:
    """{"result": ...} or {"error": one line, "kind": class name, "traceback": text}."""
    try:
        return {"result": compute(task, inputs, progress)}
    except Exception as exc:   # noqa: BLE001 - every failure goes back to the GUI as data
        message = str(exc) or type(exc).__name__
        return {"error": message.splitlines()[0] if message else type(exc).__name__,
                "kind": type(exc).__name__, "traceback": traceback.format_exc()}


def main(argv: list[str]) -> int:
    """Worker entry: IN holds a pickle of (task, inputs) written by the GUI; OUT gets the
    outcome (written whole, through fileio.atomic_write)."""
    from freecad_conformal.fileio import atomic_write
    from freecad_conformal.freecad_env import import_freecad

    if len(argv) != 2:
        print("usage: python -m freecad_conformal.objects.work IN.pickle OUT.pickle",
              file=sys.stderr)
        return 2
    with open(argv[0], "rb") as handle:
        task, inputs = pickle.load(handle)   # our own file, written by gui/worker.py
    print_progress(0.0, "starting")
    import_freecad()
    outcome = outcome_of(task, inputs, print_progress)
    with atomic_write(argv[1], "wb") as handle:
        pickle.dump(outcome, handle, protocol=4)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
