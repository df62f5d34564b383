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


def test_a_rigid_copy_keeps_the_verdict_of_occs_check(App, Part):
    """A copy only turned or moved is what its original was to OCC's check: recorded, not
    checked again (12 ms a copy of Pump_Nut), and an invalid part stays refused."""
    from freecad_conformal.geometry.solids import moved_rigidly, solids_of

    box = Part.makeBox(10, 10, 10)
    open_box = Part.Solid(Part.Shell(box.Faces[:5]))
    assert solids_of(box)
    with pytest.raises(GeometryError, match="invalid"):
        solids_of(open_box)
    for original in (box, open_box):
        copy = original.copy()
        copy.rotate(App.Vector(0, 0, 0), App.Vector(1, 1, 0), 30.0)
        copy.translate(App.Vector(5, 0, 0))
        moved_rigidly(original, copy)
        if original is box:
            assert solids_of(copy)[0].isSame(copy.Solids[0])
        else:
            with pytest.raises(GeometryError, match="invalid"):
                solids_of(copy)
