"""Shared fixtures: where the real parts are, and an artefacts folder for screenshots etc."""
from __future__ import annotations

import os
from pathlib import Path

import pytest

PROJECT_ROOT = Path(__file__).resolve().parent.parent
ARTIFACTS = PROJECT_ROOT / "tests" / "artifacts"


def shared_parts_dir() -> Path:
    return Path(os.environ.get("CONFORMAL_PARTS", PROJECT_ROOT.parent / "shared" / "parts"))


@pytest.fixture(scope="session")
def parts_dir() -> Path:
    """The real parts folder; skips (or fails under CI, CONFORMAL_REQUIRE_PARTS=1) when absent."""
    folder = shared_parts_dir()
    if not folder.is_dir():
        message = (f"real parts folder {folder} is missing (set CONFORMAL_PARTS or place "
                   "../shared/parts beside the project)")
        if os.environ.get("CONFORMAL_REQUIRE_PARTS") == "1":
            pytest.fail(message)
        pytest.skip(message)
    return folder


@pytest.fixture(scope="session")
def artifacts_dir() -> Path:
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    return ARTIFACTS


def pytest_collection_modifyitems(config, items):
    """GUI tests start FreeCAD under Xvfb (tens of seconds a module): they are slow too, so
    `./dev.sh test -m "not slow"` is the quick loop."""
    for item in items:
        if item.get_closest_marker("gui") is not None or "tests/gui/" in item.nodeid:
            item.add_marker(pytest.mark.slow)
