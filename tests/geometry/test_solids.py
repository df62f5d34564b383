"""load_shape: every supported format, and FCStd documents of PartDesign bodies."""
from __future__ import annotations

import math
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


def test_overlapping_solids_are_fused_and_touching_ones_kept(App, Part):
    """A multi-body export: bodies that overlap are one object to print (built apart they
    could never be put together), those that only touch or stand apart stay solids of
    their own (CrankArm's pin sits 0.4 mm inside its bore's clearance)."""
    from freecad_conformal.geometry.solids import united_overlaps

    box = Part.makeBox
    a, b = box(10, 10, 10), box(10, 10, 10, App.Vector(5, 5, 0))         # overlap 250 mm³
    c = box(10, 10, 10, App.Vector(12, 12, 0))                            # overlaps b only
    face_to_face = box(10, 10, 10, App.Vector(0, 0, 10))                  # touches a
    apart = box(5, 5, 5, App.Vector(40, 0, 0))
    united, note = united_overlaps(Part.makeCompound([a, b, c, face_to_face, apart]))
    assert len(united.Solids) == 3
    chain = a.fuse([b, c]).Volume
    assert sorted(s.Volume for s in united.Solids) == pytest.approx(
        sorted([chain, face_to_face.Volume, apart.Volume]), rel=1e-9)
    assert "1 and 2 by 250 mm³" in note and "2 and 3" in note and "5 solids -> 3" in note
    kept = Part.makeCompound([a, face_to_face, apart])
    assert united_overlaps(kept) == (kept, "")
    single = box(3, 3, 3)
    assert united_overlaps(single) == (single, "")


def test_a_job_prints_overlapping_bodies_as_one(App, Part):
    """Planned, two overlapping boxes are one solid, built in one piece (not laid out side
    by side as two parts), and the plan says why."""
    from freecad_conformal.jobs.plan import PlanOptions, check_options, choose_plan

    part = Part.makeCompound([Part.makeBox(10, 10, 10),
                              Part.makeBox(10, 10, 10, App.Vector(5, 5, 0))])
    options = PlanOptions()
    plan = choose_plan(part, options, check_options(part, options)).plan
    assert len(plan.subparts) == 1
    assert plan.subparts[0].volume == pytest.approx(1750.0, rel=1e-9)
    assert "fused into one solid" in plan.notes[0]


def test_decompose_fuses_overlapping_bodies_as_the_plan_does(App, Part):
    from freecad_conformal.jobs.decompose import decompose_with
    from freecad_conformal.settings.decompose import DECOMPOSE_SETTINGS
    from freecad_conformal.settings.schema import defaults

    part = Part.makeCompound([Part.makeBox(10, 10, 10),
                              Part.makeBox(10, 10, 10, App.Vector(5, 5, 0))])
    plan = decompose_with(part, defaults(DECOMPOSE_SETTINGS))
    assert len(plan.subparts) == 1 and "fused into one solid" in plan.notes[0]


def _box_with_cavity(App, Part, size: float = 30.0, wall: float = 2.0):
    inner = size - 2 * wall
    return Part.makeBox(size, size, size).cut(
        Part.makeBox(inner, inner, inner, App.Vector(wall, wall, wall))).Solids[0]


def test_closed_cavities_are_found_with_their_volumes(App, Part):
    """A box holding a closed void has two shells; the void's is the cavity. A box open to
    the outside (a cup) and a plain box have none."""
    from freecad_conformal.geometry.solids import enclosed_cavities

    assert enclosed_cavities(_box_with_cavity(App, Part)) == [pytest.approx(26.0 ** 3, rel=1e-9)]
    two = Part.makeBox(40, 40, 40).cut(Part.makeBox(10, 10, 10, App.Vector(5, 5, 5))).cut(
        Part.makeSphere(3, App.Vector(30, 30, 30))).Solids[0]
    assert sorted(enclosed_cavities(two)) == pytest.approx([4 / 3 * math.pi * 27, 1000.0],
                                                           rel=1e-9)
    cup = Part.makeBox(30, 30, 30).cut(Part.makeBox(26, 26, 30, App.Vector(2, 2, 2))).Solids[0]
    assert enclosed_cavities(cup) == []
    assert enclosed_cavities(Part.makeBox(5, 5, 5)) == []


def test_a_plan_of_a_part_with_a_closed_cavity_says_why_its_ceiling_is_left(App, Part):
    """No direction builds a closed void's ceiling support-free: the plan leaves its
    overhang and its notes say so, naming the solid and the void, instead of leaving the
    user to hunt for a cut that cannot exist."""
    from freecad_conformal.jobs.plan import PlanOptions, check_options, choose_plan

    part = Part.makeCompound([Part.makeBox(10, 10, 10, App.Vector(-60, 0, 0)),
                              _box_with_cavity(App, Part)])
    options = PlanOptions()
    plan = choose_plan(part, options, check_options(part, options)).plan
    assert plan.support_area >= 26.0 ** 2 - 1e-6      # the ceiling, whichever way it stands
    notes = [note for note in plan.notes if "closed cavit" in note]
    assert len(notes) == 1
    assert notes[0].startswith("solid 2: 1 closed cavity of 17.6 cm3")


def test_decompose_names_a_closed_cavity_as_the_plan_does(App, Part):
    from freecad_conformal.jobs.decompose import decompose_with
    from freecad_conformal.settings.decompose import DECOMPOSE_SETTINGS
    from freecad_conformal.settings.schema import defaults

    plan = decompose_with(_box_with_cavity(App, Part), defaults(DECOMPOSE_SETTINGS))
    assert [note for note in plan.notes if "closed cavit" in note] == [
        note for note in plan.notes if note.startswith("solid 1: 1 closed cavity of 17.6 cm3")]
    assert any("closed cavit" in note for note in plan.notes)
