"""Post and Verify document objects.

Post: the toolpath of the linked Job/Toolpath/Feature object posted for a machine
(post/program.post_toolpath, the `post` command's call); the G-code is kept in the document.
Verify: that G-code read back and replayed through the machine's kinematics against the
toolpath (post/verify.verify_program, the `verify` command's call).
"""
from __future__ import annotations

import math
import os
import tempfile

import FreeCAD

from freecad_conformal.objects.properties import (
    StoredState, add_properties, reports_errors, setting_properties, values_from_object)
from freecad_conformal.settings.post import POST_SETTINGS, VERIFY_SETTINGS
from freecad_conformal.settings.schema import validate


def toolpath_of(source, what: str):
    """The toolpath kept by a Job, Toolpath or Feature object."""
    from freecad_conformal.errors import PostError
    from freecad_conformal.objects.toolpath_feature import load_toolpath

    if source is None or "ToolpathFile" not in source.PropertiesList:
        raise PostError(f"{what} needs a Job, Toolpath or Feature object as its source")
    toolpath = load_toolpath(source)
    if toolpath is None:
        raise PostError(f"{what}: {source.Label} holds no toolpath yet (recompute it)")
    return toolpath


def keep_text(obj, prop: str, text: str, suffix: str) -> None:
    """Store `text` as a file included in the document."""
    handle, path = tempfile.mkstemp(suffix=suffix, prefix=f"{obj.Name}_")
    os.close(handle)
    try:
        with open(path, "w", encoding="utf-8") as out:
            out.write(text)
        setattr(obj, prop, path)
    finally:
        if os.path.exists(path):
            os.remove(path)


class PostFeature(StoredState):
    """Proxy of an App::FeaturePython: toolpath in, G-code out."""

    def __init__(self, obj) -> None:
        obj.Proxy = self
        self.setup(obj)

    def setup(self, obj) -> None:
        add_properties(obj, [
            ("App::PropertyLink", "Source", "Post", "Job, Toolpath or Feature to post", None),
            *setting_properties(POST_SETTINGS, "Post"),
            ("App::PropertyFileIncluded", "GcodeFile", "Result", "The program", None),
            ("App::PropertyInteger", "BlockCount", "Result", "Motion blocks", 0),
            ("App::PropertyFloat", "EstimatedSeconds", "Result", "Estimated run time (s)", 0.0),
        ], read_only=("BlockCount", "EstimatedSeconds"))

    def onDocumentRestored(self, obj) -> None:  # noqa: N802
        self.setup(obj)

    @reports_errors
    def execute(self, obj) -> None:
        from freecad_conformal.post.machine import load_machine
        from freecad_conformal.post.program import post_toolpath

        v = validate(POST_SETTINGS, values_from_object(obj, POST_SETTINGS))
        toolpath = toolpath_of(obj.Source, obj.Label)
        result = post_toolpath(toolpath, load_machine(v["machine"]), v["dialect"], v["tolerance"],
                               math.radians(v["angular_tolerance"]), relative_e=not v["absolute_e"])
        keep_text(obj, "GcodeFile", result.text, ".gcode")
        obj.BlockCount = int(len(result.values))
        obj.EstimatedSeconds = float(result.time_s)


class VerifyFeature(StoredState):
    """Proxy of an App::FeaturePython: replay of a Post object's G-code."""

    def __init__(self, obj) -> None:
        obj.Proxy = self
        self.setup(obj)

    def setup(self, obj) -> None:
        outputs = ("PositionDeviation", "AngleDeviation", "Passed", "Report")
        add_properties(obj, [
            ("App::PropertyLink", "Source", "Verify", "Post or Job whose program is replayed", None),
            *setting_properties(VERIFY_SETTINGS[1:], "Verify"),   # the machine is the Post's
            ("App::PropertyLength", "PositionDeviation", "Result", "Largest tip deviation", 0.0),
            ("App::PropertyAngle", "AngleDeviation", "Result", "Largest axis deviation", 0.0),
            ("App::PropertyBool", "Passed", "Result", "Both deviations within the limits", False),
            ("App::PropertyString", "Report", "Result", "The verify command's report", ""),
        ], read_only=outputs)

    def onDocumentRestored(self, obj) -> None:  # noqa: N802
        self.setup(obj)

    @reports_errors
    def execute(self, obj) -> None:
        from freecad_conformal.errors import PostError
        from freecad_conformal.post.machine import load_machine
        from freecad_conformal.post.verify import verify_file

        post = obj.Source
        if post is None or "GcodeFile" not in post.PropertiesList or not post.GcodeFile:
            raise PostError(f"{obj.Label} needs a Post object with a program as its source")
        # a Job keeps its own toolpath; a Post object's is in its source
        holder = post if "ToolpathFile" in post.PropertiesList else post.Source
        deviation = verify_file(post.GcodeFile, load_machine(post.Machine),
                                toolpath_of(holder, obj.Label))
        obj.PositionDeviation = deviation.position
        obj.AngleDeviation = math.degrees(deviation.angle)
        limits = validate(VERIFY_SETTINGS[1:], values_from_object(obj, VERIFY_SETTINGS[1:]))
        obj.Passed = bool(deviation.position <= limits["max_position"]
                          and math.degrees(deviation.angle) <= limits["max_angle"])
        obj.Report = deviation.report()
        if not obj.Passed:
            FreeCAD.Console.PrintWarning(f"Conformal: {obj.Label}: {obj.Report}\n")


def create_post(doc, source, machine: str | None = None, name: str = "Post"):
    obj = doc.addObject("App::FeaturePython", name)
    PostFeature(obj)
    obj.Source = source
    if machine:
        obj.Machine = machine
    return obj


def create_verify(doc, post, name: str = "Verify"):
    obj = doc.addObject("App::FeaturePython", name)
    VerifyFeature(obj)
    obj.Source = post
    return obj
