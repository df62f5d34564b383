"""Conformal feature document object: rods, a shell, a pattern or channels on one face of
the source body (paths/features, through the `feature` command's planners), kept as a
toolpath and drawn by the toolpath view provider."""
from __future__ import annotations

import argparse

import FreeCAD

from freecad_conformal.objects.properties import add_properties, reports_errors
from freecad_conformal.objects.toolpath_feature import (
    TOOLPATH_OUTPUTS, TOOLPATH_PROPERTIES, ToolpathFeature, store_toolpath)

GROUP = "Feature"
KINDS = ("rods", "shell", "pattern", "channels")
SECONDS_PER_MINUTE = 60.0
FEATURE_PROPERTIES = [
    ("App::PropertyLinkSub", "Source", GROUP, "Body and the face to build on", None),
    ("App::PropertyEnumeration", "Kind", GROUP, "Feature kind", KINDS),
    ("App::PropertyString", "Tool", GROUP, "Tool id (empty: the feature's default)", ""),
    ("App::PropertySpeed", "Feed", GROUP, "Curing feed (0: the tool's)", 0.0),
    ("App::PropertyLength", "LayerThickness", GROUP, "Layer thickness", 1.0),
    ("App::PropertyAngle", "Tilt", GROUP, "Tool tilt from the surface normal (shell)", 0.0),
    ("App::PropertyLength", "Spacing", GROUP, "Rod spacing on the surface", 3.0),
    ("App::PropertyLength", "RodLength", GROUP, "Rod height", 3.0),
    ("App::PropertyLength", "RodDiameter", GROUP, "Rod diameter", 1.2),
    ("App::PropertyString", "PatternText", GROUP, "Text of a pattern feature", ""),
]


def feature_arguments(obj) -> argparse.Namespace:
    """The `feature` command's arguments with the object's values (its defaults otherwise)."""
    from freecad_conformal.commands import feature as cli

    parser = argparse.ArgumentParser()
    cli.add_arguments(parser)
    face = obj.Source[1][0] if obj.Source and obj.Source[1] else "Face1"
    argv = [obj.Source[0].Label if obj.Source else "part", "--face", face, "--kind", obj.Kind,
            "-o", "unused.npz", "--layer", repr(obj.LayerThickness.Value),
            "--tilt", repr(obj.Tilt.Value), "--spacing", repr(obj.Spacing.Value),
            "--rod-length", repr(obj.RodLength.Value),
            "--rod-diameter", repr(obj.RodDiameter.Value)]
    if obj.Tool:
        argv += ["--tool", obj.Tool]
    if obj.Feed.Value > 0:   # internal unit mm/s; the command takes mm/min
        argv += ["--feed", repr(obj.Feed.Value * SECONDS_PER_MINUTE)]
    if obj.PatternText:
        argv += ["--text", obj.PatternText]
    return parser.parse_args(argv)


class ConformalFeature(ToolpathFeature):
    """Proxy of an App::FeaturePython: face + parameters in, toolpath out."""

    def setup(self, obj) -> None:
        add_properties(obj, FEATURE_PROPERTIES + TOOLPATH_PROPERTIES, read_only=TOOLPATH_OUTPUTS)

    @reports_errors
    def execute(self, obj) -> None:
        from freecad_conformal.commands import feature as cli
        from freecad_conformal.errors import GeometryError
        from freecad_conformal.geometry.faces import face_by_name

        if not obj.Source or not obj.Source[1]:
            raise GeometryError(f"{obj.Label}: select one face of a body")
        args = feature_arguments(obj)
        what = f"{args.kind} on {args.face}"
        face = face_by_name(obj.Source[0].Shape, args.face)
        store_toolpath(obj, cli._plan(args, face, what))


def create_feature(doc, body, face: str, kind: str = "rods", name: str = "Feature"):
    obj = doc.addObject("App::FeaturePython", name)
    ConformalFeature(obj)
    obj.Source = (body, [face])
    obj.Kind = kind
    if FreeCAD.GuiUp:
        from freecad_conformal.gui.view_providers import ViewProviderToolpath

        ViewProviderToolpath(obj.ViewObject)
        obj.ViewObject.ColourBy = "Kind"
    return obj
