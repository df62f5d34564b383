"""Turning inputs into jobs: globs, folders, FCStd bodies, unique G-code names, bad inputs."""
from __future__ import annotations

import math

import pytest

from freecad_conformal.jobs.batch.fcstd import body_shape, make_workbench_types_loadable, solid_bodies
from freecad_conformal.jobs.batch.jobs import expand_inputs
from freecad_conformal.errors import GeometryError
from tests.geometry.batch_parts import make_parts


@pytest.fixture(scope="module")
def parts(tmp_path_factory):
    return make_parts(tmp_path_factory.mktemp("batch-jobs"))


def test_fcstd_bodies_are_the_top_level_solids(App, tmp_path):
    """A Body and a Part::Cut are parts; the Body's feature and the Cut's box and cylinder
    (consumed by other objects) and a sketch-like wire are not."""
    make_workbench_types_loadable()
    doc = App.newDocument("BatchMixed")
    try:
        body = doc.addObject("PartDesign::Body", "Body")
        body.Label = "Bracket"
        body.addObject(doc.addObject("PartDesign::AdditiveBox", "Pad"))
        cut = doc.addObject("Part::Cut", "Cut")
        cut.Base, cut.Tool = doc.addObject("Part::Box", "Block"), doc.addObject("Part::Cylinder", "Hole")
        cut.Tool.Radius = 2
        doc.addObject("Part::Circle", "Outline")
        doc.recompute()
        doc.saveAs(str(tmp_path / "mixed.FCStd"))
    finally:
        App.closeDocument(doc.Name)
    bodies = solid_bodies(tmp_path / "mixed.FCStd")
    assert [(b.name, b.label) for b in bodies] == [("Body", "Bracket"), ("Cut", "Cut")]
    holed = body_shape(tmp_path / "mixed.FCStd", "Cut")
    # the default 10 mm cube less the quarter of the r 2 cylinder on its corner edge
    assert holed.Volume == pytest.approx(10 ** 3 - math.pi * 2 ** 2 * 10 / 4, rel=1e-9)
    with pytest.raises(GeometryError, match=r"mixed.FCStd: 'Hole' is not a solid body"):
        body_shape(tmp_path / "mixed.FCStd", "Hole")


def test_a_document_without_solids_is_a_failed_row(App, tmp_path):
    doc = App.newDocument("BatchEmpty")
    try:
        doc.addObject("Part::Circle", "Outline")
        doc.recompute()
        doc.saveAs(str(tmp_path / "empty.FCStd"))
    finally:
        App.closeDocument(doc.Name)
    (tmp_path / "corrupt.FCStd").write_bytes(b"not a zip file")
    expansion = expand_inputs([str(tmp_path / "empty.FCStd"), str(tmp_path / "corrupt.FCStd")])
    assert expansion.jobs == []
    (_, empty), (_, corrupt) = expansion.rejected
    assert empty["error"] == "empty.FCStd holds no solid body"
    assert corrupt["error"].startswith("cannot open FreeCAD document corrupt.FCStd")


def test_globs_folders_and_bodies_expand_in_order(parts):
    folder = parts["box"].parent
    expansion = expand_inputs([str(folder / "*.st*p"), str(parts["two"]), str(folder)])
    # the glob gives box.step and broken.step; the folder adds only cyl.brep (the rest is planned)
    assert [job.part for job in expansion.jobs] == [
        "box.step", "broken.step", "two.FCStd#Left", "two.FCStd#Right", "cyl.brep"]
    assert [job.index for job in expansion.jobs] == [0, 1, 2, 3, 4]
    assert [job.output for job in expansion.jobs] == [
        "box.gcode", "broken.gcode", "two_Left.gcode", "two_Right.gcode", "cyl.gcode"]
    assert expansion.jobs[2].body == "Left" and expansion.jobs[2].path == str(parts["two"])
    assert expansion.rejected == []


def test_same_names_in_two_folders_get_numbered_outputs(parts, tmp_path):
    other = tmp_path / "other"
    other.mkdir()
    (other / "BOX.step").write_bytes(parts["box"].read_bytes())
    (other / "my part#1.brep").write_bytes(parts["cyl"].read_bytes())
    expansion = expand_inputs([str(parts["box"]), str(other / "BOX.step"),
                               str(other / "my part#1.brep")], suffix=".ngc")
    assert [job.output for job in expansion.jobs] == ["box.ngc", "BOX_2.ngc", "my_part_1.ngc"]


def test_inputs_that_cannot_be_parts_are_failed_rows_in_place(parts, tmp_path):
    (tmp_path / "notes.txt").write_text("hello")
    expansion = expand_inputs([str(tmp_path / "missing.step"), str(parts["box"]),
                               str(tmp_path / "notes.txt"), str(tmp_path / "*.igs"),
                               str(tmp_path / "nothing-here")])
    assert [job.index for job in expansion.jobs] == [1]
    reasons = {index: row["error"] for index, row in expansion.rejected}
    assert reasons[0] == f"part file not found: {tmp_path / 'missing.step'}"
    assert reasons[2].startswith("cannot read notes.txt: suffix '.txt' is not one of .step")
    assert reasons[3].startswith("no part file (") and "matches" in reasons[3]
    assert reasons[4] == f"part file not found: {tmp_path / 'nothing-here'}"
    assert expansion.total == 5


def test_a_document_the_user_has_open_is_read_and_left_open(App, parts):
    doc = App.openDocument(str(parts["two"]))
    try:
        assert [b.label for b in solid_bodies(parts["two"])] == ["Left", "Right"]
        assert body_shape(parts["two"], "Right").Volume == pytest.approx(8 * 6 * 3, rel=1e-9)
        assert doc.Name in App.listDocuments()
    finally:
        App.closeDocument(doc.Name)
