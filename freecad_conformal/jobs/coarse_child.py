"""Whole orientations costed coarsely in a child Python while this process costs the others.

A part that prints support-free in several orientations has each one laid out, sliced on
every third layer and costed (`jobs/search.coarse_candidate`): work on one core, a few ms a
sampled layer. Where there is enough of it (sliced_cylinder's three orientations: 614
sampled layers), a share goes to a child Python (`child_python.py`) on the other core. The
child lays out and costs its orientations from the part in OCC's binary format with the
settings this process checked, as this process does (`jobs/coarse_work.py`, the child's
side): the same estimates, bit for bit (tests/geometry/test_coarse_child.py).
"""
from __future__ import annotations

from typing import Sequence

from freecad_conformal.child_python import ChildPython, can_start_child

#: Sampled layers a child must take for its start (interpreter, FreeCAD, the part: ~0.4 s,
#: about 100 sampled layers' work) to pay.
MIN_CHILD_LAYERS = 150
#: The child's start, in sampled layers: it begins that far behind this process.
START_LAYERS = 100


def share(weights: Sequence[float]) -> set[int]:
    """Which orientations (by index) the child takes: the heaviest first, each to whichever
    side has less to do, the child starting `START_LAYERS` behind."""
    mine, theirs = 0.0, float(START_LAYERS)
    given: set[int] = set()
    for index in sorted(range(len(weights)), key=lambda i: -weights[i]):
        if theirs < mine:
            given.add(index)
            theirs += weights[index]
        else:
            mine += weights[index]
    return given


class CoarseChild:
    """A child costing whole builds coarsely, asked at once: `numbers` are the builds'
    indices among the caller's, `roots` their (label, root direction). `results()` gives,
    per root, ("cost", PlanCost or None for no layer) or ("error", the PlanError or
    GeometryError it met); None when the child gave no answer."""

    def __init__(self, request: dict, numbers: list[int], roots: list[tuple[str, tuple]],
                 layer_settings, path_settings, motion) -> None:
        self.numbers = numbers
        self._child = ChildPython("freecad_conformal.jobs.coarse_work")
        self._child.ask({**request, "roots": roots, "layer_settings": layer_settings,
                         "path_settings": path_settings, "motion": motion})

    def results(self) -> list[tuple[str, object]] | None:
        answer = self._child.answer()
        if answer is None or not answer[0]:
            return None    # no child, or it failed as a whole: this process costs them
        return answer[1]

    def stop(self) -> None:
        self._child.stop()


def start_child(request, roots: list[tuple[str, tuple]], weights: Sequence[float],
                layer_settings, path_settings, motion) -> CoarseChild | None:
    """A child for a share of `roots` (weights: their sampled layers); None when the share
    is too small for a child to pay, or none may start. `request()` gives the part and the
    checked settings (`coarse_request`)."""
    given = sorted(share(weights))
    if not given or sum(weights[i] for i in given) < MIN_CHILD_LAYERS or not can_start_child():
        return None
    return CoarseChild(request(), given, [roots[i] for i in given], layer_settings,
                       path_settings, motion)


def coarse_request(shape, options, tool, machine) -> dict:
    """What the child needs besides the roots: the part (OCC binary) and the checked
    options, tool and machine `jobs/plan.machine_plan` lays it out with."""
    from freecad_conformal.geometry.occ_binary import to_binary

    return {"shape": to_binary(shape), "options": options, "tool": tool, "machine": machine}
