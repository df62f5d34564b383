"""The Sections document object runs on the `sections` command's settings, and files saved
before the settings schema (capitalised modes, a separate cylinder axis) still recompute."""
from __future__ import annotations

import math

import pytest


@pytest.fixture()
def doc(App):
    document = App.newDocument("SectionsObject")
    yield document
    App.closeDocument(document.Name)


def test_object_and_command_cut_the_same_sections(doc, App):
    import Part

    from freecad_conformal.geometry.report import section_report
    from freecad_conformal.objects.sections_feature import create_sections
    from freecad_conformal.settings.sections import SECTIONS_SETTINGS
    from freecad_conformal.settings.schema import defaults

    body = doc.addObject("Part::Feature", "Body")
    body.Shape = Part.makeCylinder(10, 30).fuse(Part.makeBox(40, 5, 5))
    obj = create_sections(doc, body)
    obj.Heights = "2.5, 7.5, 12.5"
    doc.recompute()
    assert obj.isValid(), obj.getStatusString()
    report = section_report(body.Shape, heights=[2.5, 7.5, 12.5])
    assert obj.LayerCount == 3
    assert obj.SectionArea.Value == pytest.approx(sum(l.area for l in report.stack.layers))
    # the object's defaults are the command's
    assert obj.LayerHeight.Value == defaults(SECTIONS_SETTINGS)["layer"]
    assert obj.Mode == "planar" and "Workers" not in obj.PropertiesList


def test_a_file_from_before_the_schema_recomputes(doc, App):
    import Part

    from freecad_conformal.objects.sections_feature import SectionsFeature

    body = doc.addObject("Part::Feature", "Rod")
    body.Shape = Part.makeCylinder(5, 40, App.Vector(0, 0, 0), App.Vector(1, 0, 0))
    old = doc.addObject("Part::FeaturePython", "OldSections")
    for type_id, name in (("App::PropertyLink", "Source"), ("App::PropertyEnumeration", "Mode"),
                          ("App::PropertyVector", "Direction"), ("App::PropertyVector", "AxisPoint"),
                          ("App::PropertyVector", "AxisDirection"),
                          ("App::PropertyLength", "RadiusStart"), ("App::PropertyLength", "RadiusEnd"),
                          ("App::PropertyLength", "RadiusStep")):
        old.addProperty(type_id, name, "Sections", "")
    old.Source = body
    old.Mode = ["Planar", "Cylindrical"]
    old.Mode = "Cylindrical"
    old.Direction, old.AxisDirection = App.Vector(0, 0, 1), App.Vector(1, 0, 0)
    old.RadiusStart, old.RadiusEnd, old.RadiusStep = 1.0, 4.0, 1.0
    proxy = SectionsFeature.__new__(SectionsFeature)
    old.Proxy = proxy
    proxy.onDocumentRestored(old)                  # what FreeCAD calls when it opens the file
    assert old.Mode == "cylindrical" and "AxisDirection" not in old.PropertiesList
    doc.recompute()
    assert old.isValid(), old.getStatusString()
    # four cylinders about the rod's own axis (X, from the old AxisDirection): 2πr·40 each
    assert old.LayerCount == 4
    assert old.SectionArea.Value == pytest.approx(2 * 3.141592653589793 * 40 * 10, rel=1e-3)


def test_a_result_read_ahead_applies_as_the_worker_wrote_it(doc, App):
    """The GUI reads a worker's shapes in one event-loop turn and applies them in the next
    (gui/background.py): the object gets the very shape, not a recomputed one."""
    import Part

    from freecad_conformal.objects.computed import precompute, read_shapes
    from freecad_conformal.objects.sections_feature import create_sections
    from freecad_conformal.objects.work import compute

    body = doc.addObject("Part::Feature", "Body")
    body.Shape = Part.makeCylinder(10, 30)
    obj = create_sections(doc, body)
    obj.Heights = "2.5, 7.5"
    doc.recompute()                             # the body as the worker would have read it
    inputs = obj.Proxy.inputs(obj)
    result = compute("sections", inputs)
    read = read_shapes(result)
    assert isinstance(result["brep"], bytes) and not isinstance(read["brep"], bytes)
    assert read_shapes(read)["brep"] is read["brep"]          # read once only
    # a result the object could not have computed itself: only a handed-in one gives it
    marker = Part.Compound([read["brep"], Part.makeCircle(1.0)])
    precompute(obj, inputs, {"result": {**read, "brep": marker, "layers": 7}})
    obj.touch()
    doc.recompute()
    assert obj.isValid(), obj.getStatusString()
    assert obj.LayerCount == 7
    assert len(obj.Shape.Edges) == len(read["brep"].Edges) + 1
    assert obj.Shape.Length == pytest.approx(read["brep"].Length + 2 * math.pi)
