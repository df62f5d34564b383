"""`python -m freecad_conformal` leaves without the interpreter's teardown (`cli.leave`):
what it prints and the handlers registered with `atexit` still come out, with its exit
code; a thread that is not a daemon still gets the ordinary exit, which waits for it."""
from __future__ import annotations

import os
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from freecad_conformal.cli import leave

ROOT = Path(__file__).resolve().parents[2]
#: Output buffered, as a plain `python` has it (PYTHONUNBUFFERED would write at each print).
BUFFERED = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"}


def _python(code: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True,
                          text=True, timeout=120, env=BUFFERED)


def test_output_and_exit_handlers_come_out_with_the_code():
    done = _python(
        "import atexit, sys\n"
        "from freecad_conformal.cli import leave\n"
        "atexit.register(lambda: print('handler ran'))\n"
        "print('x' * 100000, end='')\n"
        "print('on stderr', file=sys.stderr, end='')\n"
        "leave(3)\n")
    assert done.returncode == 3
    assert done.stdout == "x" * 100000 + "handler ran\n"
    assert done.stderr == "on stderr"


def test_a_thread_still_running_gets_the_ordinary_exit():
    release = threading.Event()
    worker = threading.Thread(target=release.wait, daemon=False)
    worker.start()
    try:
        with pytest.raises(SystemExit) as exited:
            leave(4)
        assert exited.value.code == 4
    finally:
        release.set()
        worker.join()


def test_a_reader_gone_does_not_change_the_code():
    """`plan ... | true`: the output, flushed after the reader left, is lost, not the code."""
    done = subprocess.run(
        [
            "/bin/bash", "-c",
            f"{sys.executable} -c \"import time; from freecad_conformal.cli import leave; "
            "print('y'); time.sleep(0.5); leave(5)\" | true; echo ${PIPESTATUS[0]}"],
        cwd=ROOT, capture_output=True, text=True, timeout=120, env=BUFFERED)
    assert done.stdout.strip() == "5", done.stderr
    assert "Error" not in done.stderr
