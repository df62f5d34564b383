"""load_shape: every supported format, and FCStd documents of PartDesign bodies."""
from __future__ import annotations

import subprocess
import sys

import pytest

from freecad_conformal.errors import GeometryError
from freecad_conformal.geometry.solids import load_shape
from tests.geometry.batch_parts import make_two_body_document


def test_fcstd_bodies_load_in_a_fresh_python(tmp_path):
    """From a plain Python FreeCAD drops PartDesign bodies unless its Mod folders are on
    sys.path: load_shape must see both bodies without the caller doing anything."""
    path = make_two_body_document(tmp_path / "two.FCStd")
    code = ("from freecad_conformal.geometry.solids import load_shape;"
            f"s = load_shape({str(path)!r}); print(len(s.Solids), round(s.Volume, 6))")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    count, volume = result.stdout.split()
    assert int(count) == 2 and float(volume) > 0


def test_unknown_suffix_and_missing_file(tmp_path):
    (tmp_path / "part.stl").write_text("solid x\nendsolid x\n")
    with pytest.raises(GeometryError, match="suffix"):
        load_shape(tmp_path / "part.stl")
    with pytest.raises(GeometryError, match="not found"):
        load_shape(tmp_path / "none.step")
