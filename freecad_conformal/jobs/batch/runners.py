"""Where the per-part tasks run: in this process, in a local process pool, or on Dask.

Each runner is a generator of (job, outcome) in completion order; an outcome is what
`worker.run_part` returns ({"row": ..., "gcode": ...}). A runner never stops the batch for
one part: a task that raises, or a worker that dies, becomes that part's failed row.
"""
from __future__ import annotations

import multiprocessing
import os
import sys
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from typing import Any, Callable, Iterator, Sequence

from freecad_conformal.jobs.batch.jobs import PartJob
from freecad_conformal.jobs.batch.report import failed_row
from freecad_conformal.jobs.batch.worker import run_part
from freecad_conformal.errors import ConformalError

Task = Callable[[PartJob, Any], dict]
Outcomes = Iterator[tuple[PartJob, dict]]

#: Process start methods. "spawn" starts clean interpreters (no OCC state or threads
#: inherited; the only choice on Windows and the default on macOS); "fork" starts at once
#: and is the one that works inside FreeCADCmd, whose executable cannot be re-run as Python.
START_METHODS = ("spawn", "fork", "forkserver")

def default_start_method() -> str:
    """"spawn", except inside FreeCAD (FreeCADCmd, the GUI's console), whose executable
    cannot be started as a Python worker: there "fork" where the system has it."""
    name = os.path.basename(sys.executable or "").lower()
    inside_freecad = not name.startswith("python")
    return "fork" if inside_freecad and "fork" in multiprocessing.get_all_start_methods() else "spawn"


#: Seconds to wait for a Dask scheduler before saying it cannot be reached.
DASK_CONNECT_TIMEOUT = 10.0

CRASHED = ("the worker process died while planning this part (a crash inside FreeCAD/"
           "OpenCASCADE, or out of memory)")


def _failed(job: PartJob, reason: str) -> dict:
    return {"row": failed_row(job.part, job.path, reason, job.body_label), "gcode": None}


def _call(task: Task, job: PartJob, options) -> dict:
    # A task is expected to report failures itself; anything it raises is still a row.
    try:
        return task(job, options)
    except Exception as exc:  # noqa: BLE001
        return _failed(job, f"task error ({type(exc).__name__}): {exc}")


def run_inline(jobs: Sequence[PartJob], options, task: Task = run_part) -> Outcomes:
    """Every part in this process, one after another (no isolation from crashes)."""
    for job in jobs:
        yield job, _call(task, job, options)


def run_local(jobs: Sequence[PartJob], options, workers: int, start_method: str | None = None,
              task: Task = run_part) -> Outcomes:
    """The parts on `workers` processes of this machine.

    A worker that dies breaks the whole pool, and the pool cannot tell whose part killed
    it, so the parts left unfinished are then run one per fresh process: the part that
    dies again is reported as crashed, the others complete.
    """
    if workers < 1:
        raise ConformalError(f"--workers must be at least 1 for a process pool, got {workers}")
    start_method = start_method or default_start_method()
    if start_method not in START_METHODS:
        raise ConformalError(f"start method {start_method!r} is not one of {', '.join(START_METHODS)}")
    context = multiprocessing.get_context(start_method)
    unfinished = {job.index: job for job in jobs}
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=context)
    try:
        futures = {pool.submit(task, job, options): job for job in jobs}
        for future in as_completed(futures):
            job = futures[future]
            try:
                outcome = future.result()
            except BrokenProcessPool:
                continue
            except Exception as exc:  # noqa: BLE001 (the task raised or its result did not pickle)
                outcome = _failed(job, f"task error ({type(exc).__name__}): {exc}")
            del unfinished[job.index]
            yield job, outcome
    finally:
        # On Ctrl-C (or a consumer that stops early) the queued parts are dropped, not run.
        pool.shutdown(wait=True, cancel_futures=True)
    for job in unfinished.values():
        yield job, _run_alone(job, options, context, task)


def _run_alone(job: PartJob, options, context, task: Task) -> dict:
    with ProcessPoolExecutor(max_workers=1, mp_context=context) as pool:
        try:
            return pool.submit(task, job, options).result()
        except BrokenProcessPool:
            return _failed(job, CRASHED)
        except Exception as exc:  # noqa: BLE001
            return _failed(job, f"task error ({type(exc).__name__}): {exc}")


def _dask():
    try:
        from distributed import Client, as_completed as dask_completed
    except ImportError as exc:
        raise ConformalError("--dask needs Dask's distributed scheduler, which is not installed: "
                             "pip install \"dask[distributed]\" (on this machine and the workers)"
                             ) from exc
    return Client, dask_completed


def run_dask(jobs: Sequence[PartJob], options, address: str, task: Task = run_part) -> Outcomes:
    """The parts on an existing Dask cluster (scheduler at `address`, e.g. tcp://host:8786).

    Each job carries its file's bytes, and the G-code comes back as text, so the workers
    need Conformal and FreeCAD installed but no disk shared with this machine.
    """
    Client, dask_completed = _dask()
    try:
        client = Client(address, timeout=DASK_CONNECT_TIMEOUT)
    except (OSError, TimeoutError, ValueError) as exc:
        raise ConformalError(f"cannot reach the Dask scheduler at {address!r}: {exc}") from exc
    try:
        loaded = []
        for job in jobs:
            try:
                loaded.append(job.with_data())
            except OSError as exc:
                yield job, _failed(job, f"cannot read {job.path}: {exc}")
        futures = client.map(task, loaded, options=options, pure=False)
        by_future = dict(zip(futures, loaded))
        for future in dask_completed(futures):
            job = by_future[future]
            try:
                outcome = future.result()
            except Exception as exc:  # noqa: BLE001 (a killed worker, a task that raised)
                outcome = _failed(job, f"Dask worker failed ({type(exc).__name__}): {exc}")
            yield job, outcome
    finally:
        client.close()
