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

from freecad_conformal.errors import PostError
from freecad_conformal.objects.computed import Computed
from freecad_conformal.objects.properties import (
    StoredState, add_properties, reports_errors, setting_properties, values_from_object)
from freecad_conformal.objects.toolpath_feature import toolpath_bytes
from freecad_conformal.settings.post import POST_SETTINGS, VERIFY_SETTINGS
from freecad_conformal.settings.schema import validate


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


class PostFeature(Computed, StoredState):
    """Proxy of an App::FeaturePython: toolpath in, G-code out."""

    TASK = "post"

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
        self.run(obj)

    def inputs(self, obj) -> dict:
        source = obj.Source
        if source is None or "ToolpathFile" not in source.PropertiesList:
            raise PostError(f"{obj.Label} needs a Job, Toolpath or Feature object as its source")
        v = validate(POST_SETTINGS, values_from_object(obj, POST_SETTINGS))
        return {"toolpath": toolpath_bytes(source), "machine": v["machine"],
                "dialect": v["dialect"], "tolerance": v["tolerance"],
                "angular_tolerance": math.radians(v["angular_tolerance"]),
                "relative_e": not v["absolute_e"]}

    def apply(self, obj, result: dict) -> None:
        keep_text(obj, "GcodeFile", result["gcode"], ".gcode")
        obj.BlockCount = int(result["blocks"])
        obj.EstimatedSeconds = float(result["seconds"])


def compute_post(inputs: dict, progress) -> dict:
    """G-code of toolpath bytes for a machine; the time (property and the program's header)
    is the plan's estimate (paths/timing.saved_toolpath_time: corners at the jerk the plan
    recorded in the toolpath, the machine's feed limits), so a Job and its Post report the
    same time for the same program."""
    from freecad_conformal.objects.toolpath_feature import toolpath_from_bytes
    from freecad_conformal.paths.timing import saved_toolpath_time
    from freecad_conformal.post.machine import load_machine
    from freecad_conformal.post.program import post_toolpath

    toolpath = toolpath_from_bytes(inputs["toolpath"])
    machine = load_machine(inputs["machine"])
    progress(0.1, f"posting {toolpath.segment_count} segments for {machine.name}")
    seconds = saved_toolpath_time(toolpath, machine)
    result = post_toolpath(toolpath, machine, inputs["dialect"], inputs["tolerance"],
                           inputs["angular_tolerance"],
                           relative_e=inputs.get("relative_e", True), time_s=seconds)
    return {"gcode": result.text, "blocks": int(len(result.values)), "seconds": seconds}


class VerifyFeature(Computed, StoredState):
    """Proxy of an App::FeaturePython: replay of a Post object's G-code."""

    TASK = "verify"

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
        self.run(obj)

    def inputs(self, obj) -> dict:
        post = obj.Source
        if post is None or "GcodeFile" not in post.PropertiesList or not post.GcodeFile:
            raise PostError(f"{obj.Label} needs a Post object with a program as its source")
        # a Job keeps its own toolpath; a Post object's is in its source
        holder = post if "ToolpathFile" in post.PropertiesList else post.Source
        if holder is None:
            raise PostError(f"{obj.Label}: {post.Label} has no source toolpath")
        with open(post.GcodeFile, encoding="utf-8") as handle:
            gcode = handle.read()
        return {"gcode": gcode, "machine": post.Machine, "toolpath": toolpath_bytes(holder)}

    def apply(self, obj, result: dict) -> None:
        limits = validate(VERIFY_SETTINGS[1:], values_from_object(obj, VERIFY_SETTINGS[1:]))
        obj.PositionDeviation = result["position"]
        obj.AngleDeviation = result["angle"]
        obj.Passed = bool(result["position"] <= limits["max_position"]
                          and result["angle"] <= limits["max_angle"])
        obj.Report = result["report"]
        if not obj.Passed:
            FreeCAD.Console.PrintWarning(f"Conformal: {obj.Label}: {obj.Report}\n")


def compute_verify(inputs: dict, progress) -> dict:
    """Deviations of G-code text replayed on a machine against toolpath bytes (degrees)."""
    from freecad_conformal.objects.toolpath_feature import toolpath_from_bytes
    from freecad_conformal.post.machine import load_machine
    from freecad_conformal.post.verify import verify_program

    progress(0.05, "replaying the program through the machine's kinematics")
    deviation = verify_program(inputs["gcode"], load_machine(inputs["machine"]),
                               toolpath_from_bytes(inputs["toolpath"]))
    return {"position": float(deviation.position), "angle": math.degrees(deviation.angle),
            "report": deviation.report()}


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
