"""A computation in a separate Python process (objects/work.py), so the GUI thread stays free.

Why a process and not a thread: OpenCASCADE's calls through FreeCAD's Python bindings hold
the GIL (a thread running a plan starves the GUI thread; tests/gui/test_worker.py measures
both), and a thread cannot be stopped, whereas a process ends on Cancel at once. Inside
FreeCAD `sys.executable` is the FreeCAD binary, so the worker runs the Python FreeCAD was
built for, with FreeCAD's sys.path. No Qt here: the task panel polls `poll()` from a QTimer.
"""
from __future__ import annotations

import os
import pickle
import shutil
import signal
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

from freecad_conformal import ADDON_ROOT
from freecad_conformal.freecad_env import worker_python
from freecad_conformal.objects.work import parse_progress

#: Seconds a terminated worker gets to exit before it is killed.
TERMINATE_GRACE_S = 2.0


def worker_environment() -> dict[str, str]:
    """This process's environment with its sys.path as PYTHONPATH (FreeCAD's lib and Mod
    folders, the user site with shapely, the addon itself), as multiprocessing's spawn does."""
    env = dict(os.environ)
    paths = [str(ADDON_ROOT)] + [p for p in sys.path if p and os.path.isdir(p)]
    env["PYTHONPATH"] = os.pathsep.join(dict.fromkeys(paths))
    env.pop("PYTHONHOME", None)
    return env


@dataclass
class Outcome:
    """What a finished worker gave back: a result, or an error line and its traceback."""

    result: dict | None = None
    error: str = ""
    traceback: str = ""
    cancelled: bool = False

    @property
    def ok(self) -> bool:
        return self.result is not None

    def as_precomputed(self) -> dict:
        """The form objects/computed.precompute takes."""
        return {"result": self.result} if self.ok else {"error": self.error}


class WorkerProcess:
    """One computation (objects/work.TASKS) on plain inputs in a separate process."""

    def __init__(self, task: str, inputs: dict) -> None:
        self.task, self.inputs = task, inputs
        self.folder = Path(tempfile.mkdtemp(prefix="conformal_worker_"))
        self.log = self.folder / "progress.log"
        self.result_path = self.folder / "outcome.pickle"
        self.process: subprocess.Popen | None = None
        self.outcome: Outcome | None = None
        self._log_handle = None

    def start(self) -> "WorkerProcess":
        request = self.folder / "request.pickle"
        with open(request, "wb") as handle:
            pickle.dump((self.task, self.inputs), handle, protocol=4)
        self._log_handle = open(self.log, "wb")
        self.process = subprocess.Popen(
            [worker_python(), "-m", "freecad_conformal.objects.work", str(request),
             str(self.result_path)],
            stdout=self._log_handle, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
            env=worker_environment(), cwd=str(self.folder), start_new_session=True)
        return self

    def progress(self) -> tuple[float | None, str]:
        """The last progress line the worker printed: (fraction or None, text)."""
        try:
            with open(self.log, "rb") as handle:
                handle.seek(max(0, os.path.getsize(self.log) - 4096))
                lines = handle.read().decode("utf-8", "replace").splitlines()
        except OSError:
            return None, ""
        for line in reversed(lines):
            parsed = parse_progress(line)
            if parsed is not None:
                return parsed
        return None, ""

    def poll(self) -> Outcome | None:
        """The outcome once the worker has ended, else None (call again later)."""
        if self.outcome is not None:
            return self.outcome
        if self.process is None or self.process.poll() is None:
            return None
        self.outcome = self._read_outcome(self.process.returncode)
        self._clean()
        return self.outcome

    def wait(self, timeout: float | None = None) -> Outcome:
        """Block until the worker ends (scripts and tests; the GUI polls instead)."""
        assert self.process is not None, "start() the worker first"
        self.process.wait(timeout)
        outcome = self.poll()
        assert outcome is not None
        return outcome

    def cancel(self) -> None:
        """End the worker and everything it started at once (its own process group)."""
        if self.process is not None and self.process.poll() is None:
            for sig, wait in ((signal.SIGTERM, TERMINATE_GRACE_S), (signal.SIGKILL, None)):
                try:
                    os.killpg(self.process.pid, sig)
                    self.process.wait(wait)
                    break
                except subprocess.TimeoutExpired:
                    continue
                except ProcessLookupError:
                    break
        if self.outcome is None:
            self.outcome = Outcome(error="cancelled", cancelled=True)
        self._clean()

    @property
    def running(self) -> bool:
        return self.process is not None and self.process.poll() is None

    def _read_outcome(self, code: int) -> Outcome:
        try:
            with open(self.result_path, "rb") as handle:
                data = pickle.load(handle)     # written by our own worker
        except (OSError, EOFError, pickle.UnpicklingError):
            text = self.log.read_text(encoding="utf-8", errors="replace") if self.log.exists() else ""
            last = next((line for line in reversed(text.splitlines())
                         if line.strip() and parse_progress(line) is None), "")
            return Outcome(error=f"the worker process ended (exit code {code}) without a "
                                 f"result{': ' + last if last else ''}", traceback=text)
        if "result" in data:
            return Outcome(result=data["result"])
        return Outcome(error=data.get("error", "failed"), traceback=data.get("traceback", ""))

    def _clean(self) -> None:
        if self._log_handle is not None:
            self._log_handle.close()
            self._log_handle = None
        shutil.rmtree(self.folder, ignore_errors=True)
