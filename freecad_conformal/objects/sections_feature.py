"""Sections document object: exact planar or cylindrical sections of the source body,
stored as a compound of the section wires (geometry/sections.py, geometry/cylindrical.py)."""
from __future__ import annotations

import math

import FreeCAD

from freecad_conformal.objects.computed import Computed, shape_from_text, shape_text
from freecad_conformal.objects.properties import (
    StoredState, add_properties, reports_errors, source_shape, vector3)
from freecad_conformal.tolerances import ROUNDING_SLACK

MODES = ("Planar", "Cylindrical")
GROUP = "Sections"


class SectionsFeature(Computed, StoredState):
    """Proxy of a Part::FeaturePython holding the section wires."""

    TASK = "sections"

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
        self.run(obj)

    def inputs(self, obj) -> dict:
        inputs = {"brep": shape_text(source_shape(obj, "sections")), "mode": obj.Mode,
                  "chord_tolerance": obj.ChordTolerance.Value}
        if obj.Mode == "Planar":
            inputs.update(direction=vector3(obj.Direction), layer=obj.LayerHeight.Value)
        else:
            inputs.update(radii=radii(obj), axis_point=vector3(obj.AxisPoint),
                          axis_direction=vector3(obj.AxisDirection))
        return inputs

    def apply(self, obj, result: dict) -> None:
        obj.LayerCount = result["layers"]
        obj.SectionArea = result["area"]
        obj.Shape = shape_from_text(result["brep"])


def compute_sections(inputs: dict, progress) -> dict:
    """Section wires (BREP text), non-empty layer count and area of BREP text."""
    import Part

    shape = shape_from_text(inputs["brep"])
    tolerance = inputs["chord_tolerance"]
    progress(0.1, f"{inputs['mode'].lower()} sections")
    if inputs["mode"] == "Planar":
        from freecad_conformal.geometry.sections import planar_sections

        stack = planar_sections(shape, inputs["direction"], layer=inputs["layer"],
                                chord_tolerance=tolerance)
        wires = [w for layer in stack.layers for w in layer.wires]
    else:
        from freecad_conformal.geometry.cylindrical import cylindrical_sections

        stack = cylindrical_sections(shape, inputs["radii"], inputs["axis_point"],
                                     inputs["axis_direction"], chord_tolerance=tolerance)
        wires = [w for layer in stack.layers for face in layer.faces for w in face.Wires]
    layers = [layer for layer in stack.layers if not layer.is_empty]
    if not layers:
        from freecad_conformal.errors import GeometryError

        where = (f"planes {inputs['layer']:g} mm apart along {inputs['direction']}"
                 if inputs["mode"] == "Planar" else
                 f"cylinders of radii {inputs['radii'][0]:g} to {inputs['radii'][-1]:g} mm about "
                 f"the axis through {inputs['axis_point']} along {inputs['axis_direction']}")
        raise GeometryError(f"no section: the {where} miss the part")
    return {"layers": len(layers), "area": float(sum(layer.area for layer in layers)),
            "brep": shape_text(Part.Compound(wires))}


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
