"""Where the per-part tasks run: in this process, in a local process pool, or on Dask.

Each runner is a generator of (job, outcome) in completion order; an outcome is what
`worker.run_part` returns ({"row": ..., "gcode": ...}). A runner never stops the batch for
one part: a task that raises, or a worker that dies, becomes that part's failed row.
"""
from __future__ import annotations

import math
import multiprocessing
import time
from multiprocessing.connection import wait
from typing import Any, Callable, Iterator, Sequence

from freecad_conformal.jobs.batch.jobs import PartJob
from freecad_conformal.jobs.batch.report import failed_row
from freecad_conformal.jobs.batch.worker import run_part
from freecad_conformal.errors import ConformalError

Task = Callable[[PartJob, Any], dict]
Outcomes = Iterator[tuple[PartJob, dict]]

#: Process start methods. "spawn" starts clean interpreters (no OCC state or threads
#: inherited; the only choice on Windows and the default on macOS); "fork" starts at once but
#: copies the parent as it is, which is unsafe once OCCT 7.8's Boolean thread pool has run
#: there (FreeCAD 1.x: the threads are not copied and their locks stay held).
START_METHODS = ("spawn", "fork", "forkserver")


def default_start_method() -> str:
    """"spawn", except inside FreeCAD with an OCCT whose Booleans are single-threaded
    (FreeCAD 0.20), where "fork" starts workers at once from the session's own state."""
    from freecad_conformal.freecad_env import inside_freecad
    from freecad_conformal.geometry.section_pool import THREAD_POOL_OCC, occ_version

    if inside_freecad() and "fork" in multiprocessing.get_all_start_methods() \
            and occ_version() < THREAD_POOL_OCC:
        return "fork"
    return "spawn"


def worker_context(start_method: str):
    """The multiprocessing context; inside FreeCAD, spawned workers run a real Python (the
    FreeCAD executable cannot be started as one) and get FreeCAD's sys.path from spawn's
    own preparation data."""
    from freecad_conformal.freecad_env import inside_freecad, worker_python

    context = multiprocessing.get_context(start_method)
    if start_method != "fork" and inside_freecad():
        context.set_executable(worker_python())
    return context


#: Seconds to wait for a Dask scheduler before saying it cannot be reached.
DASK_CONNECT_TIMEOUT = 10.0

CRASHED = ("the worker process died while planning this part (a crash inside FreeCAD/"
           "OpenCASCADE, or out of memory)")
#: Seconds a stopped part's process gets to exit before it is killed.
TERMINATE_GRACE_S = 2.0


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
              task: Task = run_part, time_limit: float | None = None) -> Outcomes:
    """The parts on up to `workers` processes of this machine, each part in a process of its
    own: a part that crashes its process, or runs past `time_limit` seconds (None: no limit),
    is that part's failed row and the others go on. On Ctrl-C (or a consumer that stops
    early) the running parts are ended at once and the queued ones are not started.
    """
    if workers < 1:
        raise ConformalError(f"--workers must be at least 1 for a process pool, got {workers}")
    if time_limit is not None and not (time_limit > 0 and math.isfinite(time_limit)):
        raise ConformalError(f"the per-part time limit must be a positive number of seconds, "
                             f"got {time_limit}")
    start_method = start_method or default_start_method()
    if start_method not in START_METHODS:
        raise ConformalError(f"start method {start_method!r} is not one of {', '.join(START_METHODS)}")
    context = worker_context(start_method)
    queued = list(jobs)
    running: dict[Any, _Running] = {}
    try:
        while queued or running:
            while queued and len(running) < workers:
                started = _start(context, task, queued.pop(0), options)
                running[started.receiver] = started
            deadline = min((r.deadline(time_limit) for r in running.values()), default=None)
            timeout = None if deadline is None else max(0.0, deadline - time.monotonic())
            ready = wait(list(running), timeout)
            for receiver in ready:
                done = running.pop(receiver)
                yield done.job, done.outcome()
            for receiver, late in list(running.items()):
                if late.deadline(time_limit) is not None and time.monotonic() >= late.deadline(time_limit):
                    del running[receiver]
                    late.stop()
                    yield late.job, _failed(late.job, f"stopped after the per-part time limit of "
                                                      f"{time_limit:g} s")
    finally:
        for late in running.values():
            late.stop()


class _Running:
    """One part's process, the end of the pipe its outcome comes back on, and its start."""

    def __init__(self, job: PartJob, process, receiver) -> None:
        self.job, self.process, self.receiver = job, process, receiver
        self.started = time.monotonic()

    def deadline(self, time_limit: float | None) -> float | None:
        return None if time_limit is None else self.started + time_limit

    def outcome(self) -> dict:
        """What the process sent, or the crash row when it ended without sending."""
        try:
            outcome = self.receiver.recv()
        except (EOFError, OSError):
            outcome = None
        self.process.join(TERMINATE_GRACE_S)
        self.receiver.close()
        return outcome if outcome is not None else _failed(self.job, CRASHED)

    def stop(self) -> None:
        """End the process at once (terminate, then kill) and close the pipe."""
        if self.process.is_alive():
            self.process.terminate()
            self.process.join(TERMINATE_GRACE_S)
        if self.process.is_alive():
            self.process.kill()
            self.process.join()
        self.receiver.close()


def _start(context, task: Task, job: PartJob, options) -> _Running:
    receiver, sender = context.Pipe(duplex=False)
    process = context.Process(target=_child, args=(task, job, options, sender), daemon=True,
                              name=f"conformal-batch-{job.index}")
    process.start()
    sender.close()                # the child holds the only sending end: EOF when it dies
    return _Running(job, process, receiver)


def _child(task: Task, job: PartJob, options, sender) -> None:
    """In the part's process: run the task and send its outcome (or its error) back."""
    try:
        outcome = _call(task, job, options)
        try:
            sender.send(outcome)
        except Exception as exc:  # noqa: BLE001 (an outcome that does not pickle)
            sender.send(_failed(job, f"task error ({type(exc).__name__}): {exc}"))
    finally:
        sender.close()


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
