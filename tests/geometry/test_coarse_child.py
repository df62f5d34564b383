"""Whole orientations costed coarsely in a child Python: the same estimates, bit for bit, as
costed here; the child takes only a share that pays for its start; a child that gives no
answer leaves the work to this process."""
from __future__ import annotations

from freecad_conformal.errors import PlanError
from freecad_conformal.geometry import samples
from freecad_conformal.jobs import coarse_child, search
from freecad_conformal.jobs.coarse_child import START_LAYERS, coarse_request, share
from freecad_conformal.jobs.coarse_work import coarse_costs
from freecad_conformal.jobs.plan import PlanOptions, check_options, choose_plan, machine_plan
from freecad_conformal.paths.cost import Motion


def test_the_child_takes_the_heavy_share_it_can_finish_and_nothing_small():
    # sliced_cylinder's three orientations: the child, starting behind, takes the middle one
    assert share([167.0, 218.0, 229.0]) == {1}
    # small orientations all stay here: the child's start outweighs them
    assert share([10.0, 10.0, 10.0]) == set()
    # two equal heavy ones: one each
    assert share([4 * START_LAYERS, 4 * START_LAYERS]) == {1}


#: The search's own coarse costing, before any test wraps it.
COSTED_HERE = search.coarse_candidate


def _estimates(shape, monkeypatch, child: bool) -> tuple[list, list[str]]:
    """The candidates' (label, exact, seconds, material) and the labels costed here."""
    costed_here: list[str] = []

    def counted(label, *args):
        costed_here.append(label)
        return COSTED_HERE(label, *args)

    monkeypatch.setattr(search, "coarse_candidate", counted)
    monkeypatch.setattr(coarse_child, "MIN_CHILD_LAYERS", 0.0)
    monkeypatch.setattr(coarse_child, "START_LAYERS", 0.0)
    monkeypatch.setattr(coarse_child, "can_start_child", lambda: child)
    options = PlanOptions()
    choice = choose_plan(shape, options, check_options(shape, options))
    return ([(c.label, c.exact, c.cost.seconds, c.cost.material) for c in choice.candidates],
            costed_here)


def test_a_child_costs_its_share_as_this_process_would(monkeypatch):
    shape = samples.l_block()            # four support-free orientations
    alone, all_here = _estimates(shape, monkeypatch, child=False)
    shared, some_here = _estimates(shape, monkeypatch, child=True)
    assert len(all_here) == 4 and 1 <= len(some_here) < 4
    assert shared == alone


def test_without_an_answer_from_the_child_every_orientation_is_costed_here(monkeypatch):
    shape = samples.l_block()
    alone, _ = _estimates(shape, monkeypatch, child=False)
    monkeypatch.setattr(coarse_child, "ChildPython", _Mute)
    shared, costed_here = _estimates(shape, monkeypatch, child=True)
    assert len(costed_here) == 4 and shared == alone


class _Mute(coarse_child.ChildPython):
    """A child whose module does not exist: it exits at once with no answer."""

    def __init__(self, module: str) -> None:
        super().__init__("freecad_conformal.no_such_module")


def test_the_childs_answer_names_what_it_could_not_lay_out():
    shape = samples.t_block()
    options = PlanOptions()
    tool, _, _, path_settings, machine = check_options(shape, options)
    motion = Motion.of(machine, options.jerk)
    request = {**coarse_request(shape, options, tool, machine), "layer_settings": options.layers,
               "path_settings": path_settings, "motion": motion,
               "roots": [("nowhere", (0.0, 0.0, 0.0)), ("up", (0.0, 0.0, 1.0))]}
    (kind, error), (cost_kind, cost) = coarse_costs(request)
    assert kind == "error" and isinstance(error, PlanError) and "got [0.0, 0.0, 0.0]" in str(error)
    placed, plan = machine_plan(shape, PlanOptions(root=(0.0, 0.0, 1.0), decompose=False),
                                tool=tool, machine=machine)
    here = search.coarse_candidate("up", placed, plan, options.layers, path_settings, motion)
    assert cost_kind == "cost" and cost == here.cost
