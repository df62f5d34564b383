"""The plan job, whichever the process: `plan`, `batch` and benchmarks call this."""
from __future__ import annotations

from freecad_conformal.jobs.plan import JobResult, PlanOptions, plan_additive


def plan_job(shape, options: PlanOptions, part: str = "part", library=None,
             progress=None) -> JobResult:
    """An additive plan (jobs/plan.py), or deposition and milling for `options.process`
    "hybrid" (jobs/hybrid.py), of a copy of `shape` without stored triangulations (a
    document object's shape carries its view's: `geometry/solids.without_meshes`). The
    shape caches start empty (`geometry/shape_cache.clear_all`): a process planning part
    after part keeps no shapes of the last, and every job plans as the first would."""
    from freecad_conformal.geometry.shape_cache import clear_all
    from freecad_conformal.geometry.solids import without_meshes

    clear_all()
    shape = without_meshes(shape)
    if options.process == "hybrid":
        from freecad_conformal.jobs.hybrid import plan_hybrid

        return plan_hybrid(shape, options, part, library, progress)
    return plan_additive(shape, options, part, library, progress)
