"""Sections document object: exact planar or cylindrical sections of the source body,
stored as a compound of the section wires (geometry/sections.py, geometry/cylindrical.py),
with the `sections` command's settings (settings/sections.py)."""
from __future__ import annotations

from freecad_conformal.objects.computed import Computed, shape_from_bytes, shape_to_bytes
from freecad_conformal.objects.properties import (
    StoredState, add_properties, reports_errors, setting_properties, source_shape,
    values_from_object)
from freecad_conformal.settings.sections import MODES, SECTIONS_SETTINGS

GROUP = "Sections"
SECTIONS_PROPERTIES = [
    ("App::PropertyLink", "Source", GROUP, "Body to section", None),
    *setting_properties(SECTIONS_SETTINGS, GROUP),
    ("App::PropertyInteger", "LayerCount", "Result", "Number of non-empty sections", 0),
    ("App::PropertyArea", "SectionArea", "Result", "Sum of the exact section areas", 0.0),
]


class SectionsFeature(Computed, StoredState):
    """Proxy of a Part::FeaturePython holding the section wires."""

    TASK = "sections"
    SETTINGS = SECTIONS_SETTINGS

    def __init__(self, obj) -> None:
        obj.Proxy = self
        self.setup(obj)

    def setup(self, obj) -> None:
        add_properties(obj, SECTIONS_PROPERTIES, read_only=("LayerCount", "SectionArea"))

    def onDocumentRestored(self, obj) -> None:  # noqa: N802 - FreeCAD's name
        upgrade_old_file(obj)
        self.setup(obj)

    @reports_errors
    def execute(self, obj) -> None:
        self.run(obj)

    def inputs(self, obj) -> dict:
        from freecad_conformal.settings.schema import validate
        from freecad_conformal.settings.sections import section_radii

        values = validate(SECTIONS_SETTINGS, values_from_object(obj, SECTIONS_SETTINGS))
        inputs = {"brep": shape_to_bytes(source_shape(obj, "sections")), "mode": values["mode"],
                  "chord_tolerance": values["chord"], "direction": values["direction"]}
        if values["mode"] == "planar":
            inputs.update(layer=values["layer"], heights=values["heights"])
        else:
            inputs.update(radii=section_radii(values), axis_point=values["axis_point"])
        return inputs

    def apply(self, obj, result: dict) -> None:
        obj.LayerCount = result["layers"]
        obj.SectionArea = result["area"]
        obj.Shape = shape_from_bytes(result["brep"])


def upgrade_old_file(obj) -> None:
    """Files saved before the settings schema: Mode "Planar"/"Cylindrical" becomes the
    schema's lower-case choice, and the cylinder axis (AxisDirection) moves into Direction,
    which the schema uses for both modes. Vector properties are read as they are."""
    if "Mode" in obj.PropertiesList and obj.Mode not in MODES:
        mode = str(obj.Mode).lower()
        obj.Mode = list(MODES)
        obj.Mode = mode if mode in MODES else MODES[0]
    if "AxisDirection" in obj.PropertiesList:
        if obj.Mode == "cylindrical":
            axis = obj.AxisDirection
            obj.Direction = axis if obj.getTypeIdOfProperty("Direction") == "App::PropertyVector" \
                else f"{axis.x:.12g}, {axis.y:.12g}, {axis.z:.12g}"
        obj.removeProperty("AxisDirection")


def compute_sections(inputs: dict, progress) -> dict:
    """Section wires (OCC binary), non-empty layer count and area of a shape (the same)."""
    import Part

    shape = shape_from_bytes(inputs["brep"])
    tolerance = inputs["chord_tolerance"]
    progress(0.1, f"{inputs['mode'].lower()} sections")
    if inputs["mode"] == "planar":
        from freecad_conformal.geometry.sections import planar_sections

        heights = inputs.get("heights")
        stack = planar_sections(shape, inputs["direction"],
                                layer=None if heights else inputs["layer"],
                                heights=heights or None, chord_tolerance=tolerance)
        wires = [w for layer in stack.layers for w in layer.wires]
    else:
        from freecad_conformal.geometry.cylindrical import cylindrical_sections

        stack = cylindrical_sections(shape, inputs["radii"], inputs["axis_point"],
                                     inputs["direction"], chord_tolerance=tolerance)
        wires = [w for layer in stack.layers for face in layer.faces for w in face.Wires]
    layers = [layer for layer in stack.layers if not layer.is_empty]
    if not layers:
        from freecad_conformal.errors import GeometryError

        where = (f"planes at {len(inputs['heights'])} heights along {inputs['direction']}"
                 if inputs.get("heights") else
                 f"planes {inputs['layer']:g} mm apart along {inputs['direction']}"
                 if inputs["mode"] == "planar" else
                 f"cylinders of radii {inputs['radii'][0]:g} to {inputs['radii'][-1]:g} mm about "
                 f"the axis through {inputs['axis_point']} along {inputs['direction']}")
        raise GeometryError(f"no section: the {where} miss the part")
    return {"layers": len(layers), "area": float(sum(layer.area for layer in layers)),
            "brep": shape_to_bytes(Part.Compound(wires))}


def create_sections(doc, source, mode: str = "planar", name: str = "Sections"):
    """A Sections object on `source` (gui/views.show gives it its view provider)."""
    obj = doc.addObject("Part::FeaturePython", name)
    SectionsFeature(obj)
    obj.Source = source
    obj.Mode = mode
    return obj
