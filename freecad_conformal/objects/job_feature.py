"""Job document object: the whole plan of the source body (jobs/plan.plan_job, the same
call as `python -m freecad_conformal plan`), keeping the toolpath, the G-code and the summary
in the document. It is a toolpath object, so the 3D view draws its paths."""
from __future__ import annotations

import numpy as np

from freecad_conformal.objects.computed import Computed, shape_from_bytes, shape_to_bytes
from freecad_conformal.objects.job_preview import part_frames, recording_decompose, store_preview
from freecad_conformal.objects.post_feature import keep_text
from freecad_conformal.objects.properties import (
    add_properties, reports_errors, setting_properties, source_shape, values_from_object)
from freecad_conformal.objects.toolpath_feature import (
    TOOLPATH_OUTPUTS, TOOLPATH_PROPERTIES, ToolpathFeature, store_toolpath, toolpath_from_bytes)
from freecad_conformal.settings.plan import PLAN_SETTINGS

GROUP = "Job"

#: The source, every plan setting (settings/plan.py: the same defaults and checks as the
#: `plan` command's flags) and the results.
JOB_PROPERTIES = [
    ("App::PropertyLink", "Source", GROUP, "Body to build", None),
    *setting_properties(PLAN_SETTINGS, GROUP),
    ("App::PropertyFileIncluded", "GcodeFile", "Result", "Posted G-code kept in the document", None),
    ("App::PropertyString", "Summary", "Result", "The plan summary (as the CLI prints it)", ""),
    ("App::PropertyFloat", "EstimatedSeconds", "Result", "Estimated build time in seconds", 0.0),
    ("App::PropertyInteger", "SubPartCount", "Result", "Sub-parts built", 0),
    ("App::PropertyIntegerList", "PartFrameSubparts", "Result",
     "Sub-parts whose machine-to-part motion is in PartFrames", None),
    ("App::PropertyFloatList", "PartFrames", "Result",
     "Per sub-part, the 3x4 motion from the machine frame back onto the part", None),
]
JOB_OUTPUTS = ("Summary", "EstimatedSeconds", "SubPartCount", "PartFrameSubparts", "PartFrames")


def support_segments(toolpath, roles: list[str]) -> list[int]:
    """The segments that print support: deposit segments in order are the assembly's
    paths (`roles`, theirs); none where they do not match (not an assembly toolpath)."""
    from freecad_conformal.paths.support import SUPPORT_ROLES
    from freecad_conformal.toolpath import KINDS

    deposits = np.flatnonzero(np.asarray(toolpath.kind, dtype=int) != KINDS.index("travel"))
    if len(deposits) != len(roles):
        return []
    return [int(s) for s, role in zip(deposits, roles) if role in SUPPORT_ROLES]


def segment_subparts(toolpath, deposit_subparts: list[int]) -> list[int]:
    """Sub-part of every segment: deposit segments in order are the assembly's paths; a
    travel belongs to the sub-part of the deposit after it (the last one at the end)."""
    from freecad_conformal.toolpath import KINDS

    kinds = np.asarray(toolpath.kind, dtype=int)
    deposits = np.flatnonzero(kinds != KINDS.index("travel"))
    if len(deposits) != len(deposit_subparts):
        return [0] * len(kinds)     # not an assembly toolpath: one colour
    result = np.zeros(len(kinds), dtype=int)
    result[deposits] = deposit_subparts
    following = np.searchsorted(deposits, np.arange(len(kinds)))
    travel = kinds == KINDS.index("travel")
    following = np.minimum(following, len(deposits) - 1)
    result[travel] = np.asarray(deposit_subparts)[following[travel]]
    return result.tolist()


class JobFeature(Computed, ToolpathFeature):
    """Proxy of an App::FeaturePython: parameters in, toolpath + G-code + summary out."""

    TASK = "job"
    SETTINGS = PLAN_SETTINGS

    def setup(self, obj) -> None:
        add_properties(obj, JOB_PROPERTIES + TOOLPATH_PROPERTIES,
                       read_only=JOB_OUTPUTS + TOOLPATH_OUTPUTS)

    @reports_errors
    def execute(self, obj) -> None:
        self.run(obj)

    def inputs(self, obj) -> dict:
        return {"brep": shape_to_bytes(source_shape(obj, "a job")), "part": obj.Source.Label,
                "values": values_from_object(obj, PLAN_SETTINGS)}

    def apply(self, obj, result: dict) -> None:
        store_toolpath(obj, toolpath_from_bytes(result["toolpath"]), result["segment_subparts"],
                       result.get("support_segments", ()))
        keep_text(obj, "GcodeFile", result["gcode"], ".gcode")
        obj.Summary = result["summary"]
        obj.EstimatedSeconds = float(result["seconds"])
        obj.SubPartCount = int(result["subparts"])
        store_preview(obj, result)
        report_summary(obj)


def report_summary(obj) -> None:
    """In FreeCAD's GUI, the job's summary in the Report view: the property editor shows it
    on one line, and it says what the plan costs and why overhang is left (the command
    line prints it too). A macro without the GUI reads `obj.Summary` instead."""
    import FreeCAD

    if getattr(FreeCAD, "GuiUp", False):
        FreeCAD.Console.PrintMessage(f"Conformal: {obj.Label}:\n{obj.Summary.rstrip()}\n")


def compute_job(inputs: dict, progress) -> dict:
    """The plan of a shape (OCC binary) with setting values (objects/work.py runs it anywhere): the
    steps of jobs/plan.plan_additive, with progress between them, or the hybrid job."""
    from freecad_conformal.jobs.options import plan_options as options_from_values
    from freecad_conformal.geometry.solids import solids_of
    from freecad_conformal.jobs.plan import check_options, choose_plan, run_job

    shape = shape_from_bytes(inputs["brep"])
    options = options_from_values(inputs["values"])
    if options.process == "hybrid":
        return _compute_hybrid(shape, options, inputs["part"], progress)
    progress(0.02, "checking the settings")
    checked = check_options(shape, options)     # before any geometry work, as `plan` does
    progress(0.05, "choosing the plan and placing it on the machine")
    before_layout: dict = {}
    choice = choose_plan(shape, options, checked, decompose=recording_decompose(before_layout),
                         progress=lambda text: progress(0.1, f"plan: {text}"))
    placed, plan = choice.placed, choice.plan
    if not before_layout or (choice.candidates and not choice.candidates[0].split):
        # Built whole (undecomposed, or a whole orientation won): one sub-part per solid.
        before_layout = dict(enumerate(solids_of(placed)))
    count = max(len(plan.subparts), 1)
    done: list[int] = []

    def layered(index: int) -> None:
        done.append(index)
        progress(0.4 + 0.4 * len(done) / count, f"layers of sub-part {len(done)}/{count}")

    progress(0.4, "layers")
    result = run_job(placed, plan, options, inputs["part"], progress=layered, checked=checked,
                     layers=choice.layers, candidates=choice.candidates)
    progress(0.95, "toolpath stored")
    toolpath = result.assembly.toolpath
    return {"toolpath": toolpath.to_bytes(),
            "segment_subparts": segment_subparts(toolpath,
                                                 [p.subpart for p in result.assembly.paths]),
            "support_segments": support_segments(toolpath,
                                                 [p.role for p in result.assembly.paths]),
            "gcode": result.post.text, "summary": result.summary(),
            "seconds": float(result.time_s), "subparts": len(result.subparts),
            **part_frames(shape, placed, before_layout, plan)}


def _compute_hybrid(shape, options, part: str, progress) -> dict:
    """The hybrid job (jobs/hybrid.py): the whole part moves as one (a quarter turn and a
    shift), so every sub-part has the same frame back onto the part as modelled."""
    from freecad_conformal.jobs.hybrid import plan_hybrid

    progress(0.05, "hybrid plan: deposition and milling")
    result = plan_hybrid(shape, options, part, progress=lambda text: progress(0.5, text))
    toolpath = result.assembly.toolpath
    progress(0.95, "toolpath stored")
    return {"toolpath": toolpath.to_bytes(),
            "segment_subparts": segment_subparts(toolpath,
                                                 [p.subpart for p in result.assembly.paths]),
            "gcode": result.post.text, "summary": result.summary(),
            "seconds": float(result.time_s), "subparts": len(result.subparts),
            "frame_subparts": [sub.index for sub in result.plan.subparts],
            "frames": [v for _ in result.plan.subparts for v in result.hybrid.frame_back()]}


def plan_options(obj):
    """PlanOptions from the properties, through the schema the `plan` command uses."""
    from freecad_conformal.jobs.options import plan_options as options_from_values

    return options_from_values(values_from_object(obj, PLAN_SETTINGS))


def create_job(doc, source, machine: str | None = None, name: str = "Job"):
    """A Job object on `source` (gui/commands.py gives it its view provider)."""
    obj = doc.addObject("App::FeaturePython", name)
    JobFeature(obj)
    obj.Source = source
    if machine:
        obj.Machine = machine
    return obj
