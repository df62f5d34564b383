"""Conformal feature document object: rods, a shell, a pattern or channels on one face of
the source body (jobs/feature.plan_feature, the `feature` command's call, with the same
settings schema), kept as a toolpath and drawn by the toolpath view provider. The planning
runs as the "feature" task (objects/work.py), so the GUI computes it in a worker process."""
from __future__ import annotations

from freecad_conformal.objects.computed import Computed, shape_from_bytes, shape_to_bytes
from freecad_conformal.objects.properties import (
    add_properties, reports_errors, setting_properties, values_from_object)
from freecad_conformal.objects.toolpath_feature import (
    TOOLPATH_OUTPUTS, TOOLPATH_PROPERTIES, ToolpathFeature, store_toolpath, toolpath_from_bytes)
from freecad_conformal.settings.feature import FEATURE_SETTINGS, KINDS

GROUP = "Feature"
FEATURE_PROPERTIES = [
    ("App::PropertyLinkSub", "Source", GROUP, "Body and the face to build on", None),
    ("App::PropertyEnumeration", "Kind", GROUP, "Feature kind", KINDS),
    *setting_properties(FEATURE_SETTINGS, GROUP),
]


class ConformalFeature(Computed, ToolpathFeature):
    """Proxy of an App::FeaturePython: face + parameters in, toolpath out."""

    TASK = "feature"
    SETTINGS = FEATURE_SETTINGS

    def setup(self, obj) -> None:
        add_properties(obj, FEATURE_PROPERTIES + TOOLPATH_PROPERTIES, read_only=TOOLPATH_OUTPUTS)

    @reports_errors
    def execute(self, obj) -> None:
        self.run(obj)

    def inputs(self, obj) -> dict:
        from freecad_conformal.errors import GeometryError

        if not obj.Source or not obj.Source[1]:
            raise GeometryError(f"{obj.Label}: select one face of a body")
        body, (face_name, *_) = obj.Source
        return {"brep": shape_to_bytes(body.Shape), "face": face_name, "kind": obj.Kind,
                "values": values_from_object(obj, FEATURE_SETTINGS),
                "what": f"{obj.Kind} on {face_name}"}

    def apply(self, obj, result: dict) -> None:
        store_toolpath(obj, toolpath_from_bytes(result["toolpath"]))


def compute_feature(inputs: dict, progress) -> dict:
    """The feature's toolpath from a shape (OCC binary), a face name and setting values."""
    from freecad_conformal.geometry.faces import face_by_name
    from freecad_conformal.jobs.feature import plan_feature

    progress(None, f"planning {inputs['what']}")
    part = shape_from_bytes(inputs["brep"])
    face = face_by_name(part, inputs["face"])
    toolpath = plan_feature(face, inputs["kind"], dict(inputs["values"]), inputs["what"],
                            part=part)
    return {"toolpath": toolpath.to_bytes()}


def create_feature(doc, body, face: str, kind: str = "rods", name: str = "Feature"):
    """A Feature object on `face` of `body` (gui/views.show gives it its view provider)."""
    obj = doc.addObject("App::FeaturePython", name)
    ConformalFeature(obj)
    obj.Source = (body, [face])
    obj.Kind = kind
    return obj
