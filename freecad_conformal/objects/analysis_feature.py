"""Analysis and Decomposition document objects.

Analysis: the centroidal axis of the source body (geometry/centroidal_axis.py) and the
candidate splitting faces on planes through concave edges (geometry/splitting_faces.py);
its shape is the compound of those faces. Decomposition: jobs/decompose.decompose_with (the
`decompose` command's call, the same settings schema); its shape is the compound of the sub-part solids, coloured per
sub-part. Both keep the axis as points and links for the view provider's overlay.
"""
from __future__ import annotations

import math

import FreeCAD

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


def store_axes(obj, graphs) -> None:
    """Nodes and links of every axis graph (one per solid) into the axis properties."""
    points, links, breaks, offset = [], [], [], 0
    for graph in graphs:
        points += [FreeCAD.Vector(*map(float, node.point)) for node in graph.nodes]
        for link in graph.links:
            pair = [link.start + offset, link.end + offset]
            links += pair
            if link.is_break:
                breaks += pair
        offset += len(graph.nodes)
    obj.AxisPoints, obj.AxisLinks, obj.BreakLinks = points, links, breaks


class AnalysisFeature(StoredState):
    """Proxy of a Part::FeaturePython: centroidal axis and candidate splitting faces."""

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
        import Part

        from freecad_conformal.geometry.centroidal_axis import centroidal_axis
        from freecad_conformal.geometry.concave_edges import concave_edges
        from freecad_conformal.geometry.solids import solids_of
        from freecad_conformal.geometry.splitting_faces import face_candidates

        shape = source_shape(obj, "the analysis")
        solids = solids_of(shape, obj.Label)
        graphs = [centroidal_axis(solid, method=obj.Method, step=obj.Step.Value or None,
                                  break_angle=math.radians(obj.BreakAngle.Value))
                  for solid in solids]
        faces = [c.region for solid in solids for c in face_candidates(solid, concave_edges(solid))]
        store_axes(obj, graphs)
        obj.SplittingFaceCount = len(faces)
        obj.BreakCount = len(obj.BreakLinks) // 2
        obj.Shape = Part.Compound(faces)


class DecompositionFeature(StoredState):
    """Proxy of a Part::FeaturePython: support-free sub-parts and their build order."""

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
        import Part

        from freecad_conformal.jobs.decompose import decompose_with

        shape = source_shape(obj, "the decomposition")
        plan = decompose_with(shape, values_from_object(obj, DECOMPOSE_SETTINGS))
        store_axes(obj, plan.axes)
        obj.SubPartCount = len(plan.subparts)
        obj.BuildOrder = list(plan.order)
        obj.BuildDirections = [FreeCAD.Vector(*map(float, s.build_direction)) for s in plan.subparts]
        obj.SupportAreaSaved = float(plan.support_area_saved)
        obj.Notes = list(plan.notes)
        obj.Shape = Part.Compound([s.shape for s in plan.subparts])


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
