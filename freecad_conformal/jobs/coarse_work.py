"""The coarse child's side (`jobs/coarse_child.py`): whole builds laid out and costed on
sampled layers as `jobs/search.py` costs them, from the part in OCC's binary format."""
from __future__ import annotations

import dataclasses

from freecad_conformal.child_python import serve
from freecad_conformal.errors import GeometryError, PlanError


def coarse_costs(request: dict) -> list[tuple[str, object]]:
    """The child's answer: each root laid out whole and costed on sampled layers."""
    from freecad_conformal.geometry.occ_binary import from_binary
    from freecad_conformal.jobs.plan import machine_plan
    from freecad_conformal.jobs.search import coarse_candidate

    shape = from_binary(request["shape"])
    out: list[tuple[str, object]] = []
    for label, root in request["roots"]:
        options = dataclasses.replace(request["options"], root=root, decompose=False)
        try:
            placed, plan = machine_plan(shape, options, None, tool=request["tool"],
                                        machine=request["machine"])
            made = coarse_candidate(label, placed, plan, request["layer_settings"],
                                    request["path_settings"], request["motion"])
        except (PlanError, GeometryError) as exc:
            out.append(("error", exc))
            continue
        out.append(("cost", None if made is None else made.cost))
    return out


def _preload() -> None:
    # Loaded while the parent lays out its first orientation.
    from freecad_conformal.jobs import plan, search  # noqa: F401


if __name__ == "__main__":
    serve(coarse_costs, _preload)
