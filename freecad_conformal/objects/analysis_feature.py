"""Analysis and Decomposition document objects.

Analysis: the centroidal axis of the source body (geometry/centroidal_axis.py) and the
candidate splitting faces on planes through concave edges (geometry/splitting_faces.py);
its shape is the compound of those faces. Decomposition: jobs/decompose.decompose_with (the
`decompose` command's call, the same settings schema); its shape is the compound of the sub-part solids, coloured per
sub-part. Both keep the axis as points and links for the view provider's overlay.
"""
from __future__ import annotations

import FreeCAD

from freecad_conformal.objects.computed import Computed, shape_from_bytes, shape_to_bytes
from freecad_conformal.objects.properties import (
    StoredState, add_properties, reports_errors, setting_properties, source_shape,
    values_from_object)
from freecad_conformal.settings.decompose import DECOMPOSE_SETTINGS, METHODS

AXIS_PROPERTIES = [
    ("App::PropertyVectorList", "AxisPoints", "Axis", "Centroids of the axis nodes", None),
    ("App::PropertyIntegerList", "AxisLinks", "Axis", "Node index pairs of the axis links", None),
    ("App::PropertyIntegerList", "BreakLinks", "Axis", "Node index pairs of the C1 break links", None),
]
AXIS_OUTPUTS = ("AxisPoints", "AxisLinks", "BreakLinks")


def store_axes(obj, axes: dict) -> None:
    """Plain axes (analysis_compute.plain_axes) into the axis properties."""
    obj.AxisPoints = [FreeCAD.Vector(*p) for p in axes["points"]]
    obj.AxisLinks, obj.BreakLinks = axes["links"], axes["breaks"]


class AnalysisFeature(Computed, StoredState):
    """Proxy of a Part::FeaturePython: centroidal axis and candidate splitting faces."""

    TASK = "analysis"

    def __init__(self, obj) -> None:
        obj.Proxy = self
        self.setup(obj)

    def setup(self, obj) -> None:
        add_properties(obj, [
            ("App::PropertyLink", "Source", "Analysis", "Body to analyse", None),
            ("App::PropertyEnumeration", "Method", "Analysis",
             "Follow inclined members, or turn to the nearest of ±X, ±Y, ±Z", METHODS),
            ("App::PropertyLength", "Step", "Analysis", "Section step (0: 1/40 of the height)", 0.0),
            ("App::PropertyAngle", "BreakAngle", "Analysis", "Direction change marking a C1 break", 45.0),
            ("App::PropertyInteger", "SplittingFaceCount", "Result", "Candidate splitting faces", 0),
            ("App::PropertyInteger", "BreakCount", "Result", "C1 break links of the axis", 0),
        ] + AXIS_PROPERTIES, read_only=("SplittingFaceCount", "BreakCount") + AXIS_OUTPUTS)

    def onDocumentRestored(self, obj) -> None:  # noqa: N802
        self.setup(obj)

    @reports_errors
    def execute(self, obj) -> None:
        self.run(obj)

    def inputs(self, obj) -> dict:
        return {"brep": shape_to_bytes(source_shape(obj, "the analysis")), "label": obj.Label,
                "method": obj.Method, "step": obj.Step.Value or None,
                "break_angle": obj.BreakAngle.Value}

    def apply(self, obj, result: dict) -> None:
        store_axes(obj, result["axes"])
        obj.SplittingFaceCount = result["faces"]
        obj.BreakCount = len(obj.BreakLinks) // 2
        obj.Shape = shape_from_bytes(result["brep"])


class DecompositionFeature(Computed, StoredState):
    """Proxy of a Part::FeaturePython: support-free sub-parts and their build order."""

    TASK = "decomposition"
    SETTINGS = DECOMPOSE_SETTINGS

    def __init__(self, obj) -> None:
        obj.Proxy = self
        self.setup(obj)

    def setup(self, obj) -> None:
        outputs = ("SubPartCount", "BuildOrder", "BuildDirections", "SupportAreaSaved", "Notes")
        add_properties(obj, [
            ("App::PropertyLink", "Source", "Decomposition", "Body to decompose", None),
            *setting_properties(DECOMPOSE_SETTINGS, "Decomposition"),
            ("App::PropertyInteger", "SubPartCount", "Result", "Sub-parts", 0),
            ("App::PropertyIntegerList", "BuildOrder", "Result", "Sub-part indices in build order", None),
            ("App::PropertyVectorList", "BuildDirections", "Result", "Build direction per sub-part", None),
            ("App::PropertyArea", "SupportAreaSaved", "Result",
             "Overhang area saved against the best single direction", 0.0),
            ("App::PropertyStringList", "Notes", "Result", "What the decomposition noticed", None),
        ] + AXIS_PROPERTIES, read_only=outputs + AXIS_OUTPUTS)

    def onDocumentRestored(self, obj) -> None:  # noqa: N802
        self.setup(obj)

    @reports_errors
    def execute(self, obj) -> None:
        self.run(obj)

    def inputs(self, obj) -> dict:
        return {"brep": shape_to_bytes(source_shape(obj, "the decomposition")),
                "values": values_from_object(obj, DECOMPOSE_SETTINGS)}

    def apply(self, obj, result: dict) -> None:
        store_axes(obj, result["axes"])
        obj.SubPartCount = result["subparts"]
        obj.BuildOrder = result["order"]
        obj.BuildDirections = [FreeCAD.Vector(*d) for d in result["directions"]]
        obj.SupportAreaSaved = result["saved"]
        obj.Notes = result["notes"]
        obj.Shape = shape_from_bytes(result["brep"])


def _create(doc, proxy_class, source, name: str):
    obj = doc.addObject("Part::FeaturePython", name)
    proxy_class(obj)
    obj.Source = source
    return obj


def create_analysis(doc, source, name: str = "Analysis"):
    """An Analysis object on `source` (gui/views.show gives it its view provider)."""
    return _create(doc, AnalysisFeature, source, name)


def create_decomposition(doc, source, name: str = "Decomposition"):
    """A Decomposition object on `source` (gui/views.show gives it its view provider)."""
    return _create(doc, DecompositionFeature, source, name)
