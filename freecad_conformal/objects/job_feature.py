"""Job document object: the whole plan of the source body (jobs/plan.plan_job, the same
call as `python -m freecad_conformal plan`), keeping the toolpath, the G-code and the summary
in the document. It is a toolpath object, so the 3D view draws its paths."""
from __future__ import annotations

import os
import tempfile

import numpy as np

from freecad_conformal.objects.properties import (
    add_properties, reports_errors, setting_properties, source_shape, values_from_object)
from freecad_conformal.objects.toolpath_feature import (
    TOOLPATH_OUTPUTS, TOOLPATH_PROPERTIES, ToolpathFeature, store_toolpath)
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
]
JOB_OUTPUTS = ("Summary", "EstimatedSeconds", "SubPartCount")


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


class JobFeature(ToolpathFeature):
    """Proxy of an App::FeaturePython: parameters in, toolpath + G-code + summary out."""

    def setup(self, obj) -> None:
        add_properties(obj, JOB_PROPERTIES + TOOLPATH_PROPERTIES,
                       read_only=JOB_OUTPUTS + TOOLPATH_OUTPUTS)

    @reports_errors
    def execute(self, obj) -> None:
        from freecad_conformal.jobs.plan import plan_job

        # plan_job checks every setting before any geometry work, as the command line does
        result = plan_job(source_shape(obj, "a job"), plan_options(obj), part=obj.Source.Label)
        toolpath = result.assembly.toolpath
        store_toolpath(obj, toolpath,
                       segment_subparts(toolpath, [p.subpart for p in result.assembly.paths]))
        handle, path = tempfile.mkstemp(suffix=".gcode", prefix=f"{obj.Name}_")
        os.close(handle)
        try:
            with open(path, "w", encoding="utf-8") as out:
                out.write(result.post.text)
            obj.GcodeFile = path
        finally:
            if os.path.exists(path):
                os.remove(path)
        obj.Summary = result.summary()
        obj.EstimatedSeconds = float(result.time_s)
        obj.SubPartCount = len(result.subparts)


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
