"""Sections document object: exact planar or cylindrical sections of the source body,
stored as a compound of the section wires (geometry/sections.py, geometry/cylindrical.py)."""
from __future__ import annotations

import math

import FreeCAD

from freecad_conformal.objects.properties import reports_errors, StoredState, add_properties, source_shape, vector3
from freecad_conformal.tolerances import ROUNDING_SLACK

MODES = ("Planar", "Cylindrical")
GROUP = "Sections"


class SectionsFeature(StoredState):
    """Proxy of a Part::FeaturePython holding the section wires."""

    def __init__(self, obj) -> None:
        obj.Proxy = self
        self.setup(obj)

    def setup(self, obj) -> None:
        from freecad_conformal.tolerances import DEFAULT_CHORD_TOLERANCE

        add_properties(obj, [
            ("App::PropertyLink", "Source", GROUP, "Body to section", None),
            ("App::PropertyEnumeration", "Mode", GROUP, "Planar layers or coaxial cylinders", MODES),
            ("App::PropertyVector", "Direction", GROUP, "Build direction (planar)",
             FreeCAD.Vector(0, 0, 1)),
            ("App::PropertyLength", "LayerHeight", GROUP, "Layer spacing (planar)", 1.0),
            ("App::PropertyVector", "AxisPoint", GROUP, "Point on the cylinder axis (mm)",
             FreeCAD.Vector(0, 0, 0)),
            ("App::PropertyVector", "AxisDirection", GROUP, "Cylinder axis direction",
             FreeCAD.Vector(0, 0, 1)),
            ("App::PropertyLength", "RadiusStart", GROUP, "First cylinder radius", 1.0),
            ("App::PropertyLength", "RadiusEnd", GROUP, "Last cylinder radius", 10.0),
            ("App::PropertyLength", "RadiusStep", GROUP, "Radial spacing", 1.0),
            ("App::PropertyLength", "ChordTolerance", GROUP,
             "Polygon tolerance of the loops", DEFAULT_CHORD_TOLERANCE),
            ("App::PropertyInteger", "LayerCount", "Result", "Number of non-empty sections", 0),
            ("App::PropertyArea", "SectionArea", "Result", "Sum of the exact section areas", 0.0),
        ], read_only=("LayerCount", "SectionArea"))

    def onDocumentRestored(self, obj) -> None:  # noqa: N802 - FreeCAD's name
        self.setup(obj)

    @reports_errors
    def execute(self, obj) -> None:
        import Part

        shape = source_shape(obj, "sections")
        tolerance = obj.ChordTolerance.Value
        if obj.Mode == "Planar":
            from freecad_conformal.geometry.sections import planar_sections

            stack = planar_sections(shape, vector3(obj.Direction), layer=obj.LayerHeight.Value,
                                    chord_tolerance=tolerance)
            wires = [w for layer in stack.layers for w in layer.wires]
        else:
            from freecad_conformal.geometry.cylindrical import cylindrical_sections

            stack = cylindrical_sections(shape, radii(obj), vector3(obj.AxisPoint),
                                         vector3(obj.AxisDirection), chord_tolerance=tolerance)
            wires = [w for layer in stack.layers for face in layer.faces for w in face.Wires]
        layers = [layer for layer in stack.layers if not layer.is_empty]
        obj.LayerCount = len(layers)
        obj.SectionArea = float(sum(layer.area for layer in layers))
        obj.Shape = Part.Compound(wires)


def radii(obj) -> list[float]:
    """Cylinder radii from RadiusStart to RadiusEnd by RadiusStep (both ends included)."""
    from freecad_conformal.errors import GeometryError

    start, end, step = obj.RadiusStart.Value, obj.RadiusEnd.Value, obj.RadiusStep.Value
    if step <= 0 or end < start:
        raise GeometryError(f"{obj.Label}: radii from {start:g} to {end:g} mm by {step:g} mm "
                            "need step > 0 and end >= start")
    count = int(math.floor((end - start) / step + ROUNDING_SLACK)) + 1
    return [start + k * step for k in range(count)]


def create_sections(doc, source, mode: str = "Planar", name: str = "Sections"):
    """A Sections object on `source` (gui/views.show gives it its view provider)."""
    obj = doc.addObject("Part::FeaturePython", name)
    SectionsFeature(obj)
    obj.Source = source
    obj.Mode = mode
    return obj
