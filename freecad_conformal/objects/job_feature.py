"""Job document object: the whole plan of the source body (planning/job.run_job, the same
call as `python -m freecad_conformal plan`), keeping the toolpath, the G-code and the summary
in the document. It is a toolpath object, so the 3D view draws its paths."""
from __future__ import annotations

import os
import tempfile

import FreeCAD
import numpy as np

from freecad_conformal.objects.analysis_feature import root_direction, root_property
from freecad_conformal.objects.properties import reports_errors, add_properties, source_shape
from freecad_conformal.objects.toolpath_feature import (
    TOOLPATH_OUTPUTS, TOOLPATH_PROPERTIES, ToolpathFeature, store_toolpath)

GROUP = "Job"


def _machines() -> tuple[str, ...]:
    from freecad_conformal import RESOURCES

    names = sorted(p.stem for p in (RESOURCES / "machines").glob("*.json"))
    # the command line's default machine comes first (an enumeration's default)
    return tuple(sorted(names, key=lambda name: name != "trunnion_ac"))


JOB_PROPERTIES = [
    ("App::PropertyLink", "Source", GROUP, "Body to build", None),
    ("App::PropertyEnumeration", "Machine", GROUP, "Machine (resources/machines)", _machines()),
    ("App::PropertyString", "Tool", GROUP, "Tool id in the tool library", "fdm_0p4"),
    ("App::PropertyString", "Material", GROUP, "Material of the tool's settings (empty: first)", ""),
    ("App::PropertyLength", "LayerHeight", GROUP, "Layer height", 0.2),
    ("App::PropertyLength", "BeadWidth", GROUP, "Bead width (0: the material's)", 0.0),
    ("App::PropertyInteger", "Perimeters", GROUP, "Perimeter loops per layer", 2),
    ("App::PropertyPercent", "Infill", GROUP, "Sparse infill density", 20),
    ("App::PropertyBool", "TiltLayers", GROUP, "Allow 3-D (tilted) layers (plan --tilt)", False),
    ("App::PropertyBool", "Decompose", GROUP, "Split into support-free sub-parts", True),
    root_property(GROUP),
    ("App::PropertyString", "Dialect", GROUP, "G-code dialect (empty: the machine's)", ""),
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
        from freecad_conformal.jobs.plan import run_job

        shape, plan = build_plan(obj, source_shape(obj, "a job"))
        result = run_job(shape, plan, plan_options(obj), part=obj.Source.Label)
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


def build_plan(obj, shape):
    """(placed shape, plan) as the plan command makes it: decomposed into sub-parts when
    asked, else one per solid; solids on the platform, the part turned if the machine needs."""
    from freecad_conformal.jobs.plan import machine_plan

    return machine_plan(shape, plan_options(obj), split=obj.Decompose)


def plan_options(obj):
    """PlanOptions from the properties, as `plan`'s options_from builds them from flags."""
    from freecad_conformal.paths.assemble import PathSettings
    from freecad_conformal.paths.fill2d import FillSettings
    from freecad_conformal.jobs.plan import PlanOptions
    from freecad_conformal.layers.model import LayerSettings

    width = obj.BeadWidth.Value or None
    fill = FillSettings(bead_width=width or 0.4, perimeters=obj.Perimeters,
                        density=obj.Infill / 100.0)
    layers = LayerSettings(thickness=obj.LayerHeight.Value, tilt=obj.TiltLayers)
    return PlanOptions(machine=obj.Machine, tool=obj.Tool, material=obj.Material or None,
                       layers=layers, paths=PathSettings(fill=fill), bead_width=width,
                       dialect=obj.Dialect or None, root=root_direction(obj))


def create_job(doc, source, machine: str | None = None, name: str = "Job"):
    """A Job object on `source` (drawn by the toolpath view provider when the GUI is up)."""
    obj = doc.addObject("App::FeaturePython", name)
    JobFeature(obj)
    obj.Source = source
    if machine:
        obj.Machine = machine
    if FreeCAD.GuiUp:
        from freecad_conformal.gui.view_providers import ViewProviderToolpath

        ViewProviderToolpath(obj.ViewObject)
    return obj
