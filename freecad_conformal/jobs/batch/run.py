"""`run_batch`: inputs -> jobs -> runner -> one G-code file per part + CSV/JSON report."""
from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

from freecad_conformal.jobs.batch import runners
from freecad_conformal.jobs.batch.jobs import expand_inputs
from freecad_conformal.jobs.batch.report import FAILED, counts, failed_row, write_report
from freecad_conformal.jobs.batch.worker import run_part
from freecad_conformal.errors import ConformalError, OutputError
from freecad_conformal.fileio import guard_outputs, make_output_folder, write_text_atomic

REPORT_STEM = "batch-report"


@dataclass
class BatchResult:
    """The rows in input order and the report files."""

    rows: list[dict]
    csv_path: Path
    json_path: Path

    @property
    def failed(self) -> int:
        return counts(self.rows)[FAILED]


def check_plan_options(options) -> None:
    """What can be checked without a part (tool, material, machine, layer settings), so a
    typo fails the batch at once instead of failing every part."""
    from freecad_conformal.jobs.plan import resolve_tool
    from freecad_conformal.post.machine import load_machine

    options.layers.validate()
    resolve_tool(options.tool, options.material)
    load_machine(options.machine)


#: Default per-part time limit (s) of local workers: a part that stalls (a corrupt file in
#: FreeCAD's reader, a runaway plan) is stopped and reported instead of holding the batch.
PART_TIME_LIMIT = 3600.0
#: The row of a part that had not finished when the user pressed Ctrl-C.
INTERRUPTED = "interrupted (Ctrl-C) before this part finished"


def _outcomes(jobs, options, workers: int, dask: str | None, start_method: str, task,
              time_limit: float | None):
    if dask:
        return runners.run_dask(jobs, options, dask, task)
    if workers == 0:
        return runners.run_inline(jobs, options, task)
    return runners.run_local(jobs, options, workers, start_method, task, time_limit)


def run_batch(inputs: Sequence[str], options, out_dir: str | Path, *, workers: int = 1,
              dask: str | None = None, start_method: str | None = None, suffix: str = ".gcode",
              make_progress=None, task=run_part,
              time_limit: float | None = PART_TIME_LIMIT) -> BatchResult:
    """Plan and post every part of `inputs`; write the G-code files and the report in `out_dir`.

    Args:
        inputs: files, folders or globs of STEP, BREP, IGES and FCStd (one part per body).
        options: planning.job.PlanOptions for every part.
        workers: local processes (0: in this process); ignored when `dask` is given.
        dask: address of a Dask scheduler to send the parts to.
        start_method: how local workers start ("spawn", "fork", "forkserver"; None:
            runners.default_start_method()).
        suffix: G-code file suffix.
        make_progress: total -> a progress.Progress (update, close), or None for none.
        task: the per-part function (tests replace it to simulate crashes).
        time_limit: seconds a part may take on a local worker before it is stopped and
            failed (None: no limit; parts planned in this process cannot be stopped).
    Returns:
        BatchResult; parts that failed are rows with status "failed" and the reason.
    Raises:
        ConformalError: bad options, or a Dask scheduler that cannot be reached.
        KeyboardInterrupt: after the report of the parts finished so far is written (the
            others are rows that say they were interrupted).
    """
    if not suffix.startswith(".") or len(suffix) < 2:
        raise ConformalError(f"G-code suffix must start with a dot, like .gcode, got {suffix!r}")
    if any(sep in suffix for sep in ("/", "\\", os.sep)) or ".." in suffix:
        raise ConformalError(f"G-code suffix {suffix!r} must not hold a folder separator or '..': "
                             "every file stays in the output folder")
    check_plan_options(options)
    out = make_output_folder(out_dir)
    expansion = expand_inputs(inputs, suffix)
    rows = dict(expansion.rejected)
    progress = make_progress(expansion.total) if make_progress is not None else None
    interrupted = False
    try:
        if progress is not None:
            progress.update(len(rows))
        if expansion.jobs:
            outcomes = _outcomes(expansion.jobs, options, workers, dask, start_method, task,
                                 time_limit)
            try:
                for job, outcome in outcomes:
                    rows[job.index] = _store(outcome, out / job.output, job.path)
                    if progress is not None:
                        progress.update(1)
            except KeyboardInterrupt:
                interrupted = True
                close = getattr(outcomes, "close", None)
                if close is not None:
                    close()                      # ends the running parts' processes now
                for job in expansion.jobs:
                    rows.setdefault(job.index, failed_row(job.part, job.path, INTERRUPTED,
                                                          job.body_label))
    finally:
        if progress is not None:
            progress.close()
    ordered = [rows[index] for index in sorted(rows)]
    settings = {"inputs": list(inputs), "runner": f"dask {dask}" if dask else
                ("in-process" if workers == 0 else f"{workers} local workers"),
                "options": dataclasses.asdict(options)}
    if options.settings:                   # the user's settings, as `plan --report` gives them
        from freecad_conformal.settings.plan import PLAN_SETTINGS
        from freecad_conformal.settings.schema import as_json

        settings["settings"] = as_json(PLAN_SETTINGS, options.settings)
    csv_path, json_path = out / f"{REPORT_STEM}.csv", out / f"{REPORT_STEM}.json"
    write_report(ordered, csv_path, json_path, settings)
    if interrupted:
        raise KeyboardInterrupt(f"batch interrupted; report of the parts so far: {csv_path}")
    return BatchResult(ordered, csv_path, json_path)


def _store(outcome: dict, path: Path, source: str) -> dict:
    """Write the part's G-code (atomically); a disk error, or a G-code path that is the part's
    own file, fails only this part."""
    row = outcome["row"]
    if outcome["gcode"] is None:
        return row
    try:
        guard_outputs([source], {"G-code": path})
        write_text_atomic(path, outcome["gcode"])
    except (OSError, OutputError) as exc:
        row.update(status=FAILED, error=str(exc))
        return row
    row["gcode"] = path.name
    return row
