"""Lint as part of the tests, so CI refuses unused imports, undefined names and the like."""
from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def _ruff() -> list[str]:
    beside = Path(sys.executable).with_name("ruff")
    if beside.exists():
        return [str(beside)]
    found = shutil.which("ruff")
    if found is None:
        pytest.skip("ruff is not installed (requirements-test.txt has it)")
    return [found]


def test_ruff_finds_nothing():
    result = subprocess.run([*_ruff(), "check", "--no-cache", "freecad_conformal", "tests",
                             "benchmarks"], cwd=ROOT, capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr


#: Modules held to their type hints: the pure rooms and the base modules.
TYPED = ["freecad_conformal/settings", "freecad_conformal/toolpath.py",
         "freecad_conformal/post", "freecad_conformal/stream", "freecad_conformal/process",
         "freecad_conformal/errors.py", "freecad_conformal/tolerances.py",
         "freecad_conformal/fileio.py", "freecad_conformal/progress.py"]


@pytest.mark.slow
def test_typed_modules_pass_mypy():
    import numpy

    if int(numpy.__version__.split(".")[0]) >= 2:
        # numpy 2's stubs type .tolist() and comparisons differently; the types are held
        # against the numpy 1.x leg (FreeCAD 0.20 on Debian 12), which CI runs first.
        pytest.skip("mypy runs on the numpy 1.x leg")
    mypy = Path(sys.executable).with_name("mypy")
    if not mypy.exists():
        pytest.skip("mypy is not installed (requirements-test.txt has it)")
    result = subprocess.run([str(mypy), "--ignore-missing-imports", "--follow-imports=silent",
                             "--no-incremental", *TYPED], cwd=ROOT, capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr
