"""Geometry tests need FreeCAD's Part module (headless)."""
from __future__ import annotations

import pytest

from freecad_conformal.freecad_env import import_freecad


@pytest.fixture(scope="session")
def fc():
    """(FreeCAD, Part) modules."""
    return import_freecad()


@pytest.fixture(scope="session")
def App(fc):
    return fc[0]


@pytest.fixture(scope="session")
def Part(fc):
    return fc[1]
