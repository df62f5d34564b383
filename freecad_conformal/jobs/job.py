"""The plan job, whichever the process: `plan`, `batch` and benchmarks call this."""
from __future__ import annotations

from freecad_conformal.jobs.plan import JobResult, PlanOptions, plan_additive


def plan_job(shape, options: PlanOptions, part: str = "part", library=None,
             progress=None) -> JobResult:
    """An additive plan (jobs/plan.py), or deposition and milling for `options.process`
    "hybrid" (jobs/hybrid.py), of a copy of `shape` without stored triangulations (a
    document object's shape carries its view's: `geometry/solids.without_meshes`)."""
    from freecad_conformal.geometry.solids import without_meshes

    shape = without_meshes(shape)
    if options.process == "hybrid":
        from freecad_conformal.jobs.hybrid import plan_hybrid

        return plan_hybrid(shape, options, part, library, progress)
    return plan_additive(shape, options, part, library, progress)
