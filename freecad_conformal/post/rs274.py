"""Run LinuxCNC's own interpreter (`rs274 -g`, Debian package linuxcnc-uspace) on a program
and read back its canonical moves, to check LinuxCNC output independently of our reader."""
from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import numpy as np

from freecad_conformal.errors import PostError

_CANONICAL = re.compile(r"(STRAIGHT_FEED|STRAIGHT_TRAVERSE)\(([^)]*)\)")

#: rs274 stops at the first error but can hang waiting on a tool table when misconfigured.
TIMEOUT_S = 120


def rs274_path() -> str | None:
    """The interpreter's path, or None when LinuxCNC is not installed."""
    return shutil.which("rs274")


def canonical_moves(program: str | Path) -> tuple[list[str], np.ndarray]:
    """Interpret `program`; return each move's kind and (x, y, z, a, b, c) values.

    Raises PostError when rs274 is missing or rejects the program (with its message).
    """
    executable = rs274_path()
    if executable is None:
        raise PostError("rs274 (LinuxCNC's interpreter, Debian package linuxcnc-uspace) is not installed")
    completed = subprocess.run([executable, "-g", str(program)], capture_output=True, text=True,
                               timeout=TIMEOUT_S, stdin=subprocess.DEVNULL, check=False)
    if completed.returncode != 0:
        raise PostError(f"rs274 rejected {program}: {completed.stdout[-400:]} {completed.stderr[-400:]}")
    kinds, values = [], []
    for match in _CANONICAL.finditer(completed.stdout):
        numbers = [float(v) for v in match.group(2).split(",")]
        kinds.append("feed" if match.group(1) == "STRAIGHT_FEED" else "traverse")
        values.append(numbers[:6])
    return kinds, np.array(values, dtype=float).reshape(-1, 6)
