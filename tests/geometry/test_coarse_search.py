"""Whole orientations ranked on sampled layers first: the sample stands for the stack, its
cost is close to the exact one, and the choice is the one exact costing would make."""
from __future__ import annotations

import re

import numpy as np
import pytest

from freecad_conformal.decomposition.subparts import SubPart
from freecad_conformal.errors import PlanError
from freecad_conformal.geometry import samples
from freecad_conformal.jobs import search
from freecad_conformal.jobs.plan import PlanOptions, check_options, choose_plan
from freecad_conformal.layers.model import LayerSettings
from freecad_conformal.layers.plan import plan_layers, sampled_layers


def _whole(shape, direction) -> SubPart:
    return SubPart(index=0, shape=shape, build_direction=np.asarray(direction, dtype=float),
                   volume=float(shape.Volume))


@pytest.mark.parametrize("every", [1, 3, 4])
def test_sampled_layers_are_layers_of_the_stack_standing_for_it(every):
    sub = _whole(samples.t_block(), (0.0, 0.0, 1.0))
    settings = LayerSettings(tilt=False)
    stack = plan_layers(sub, settings)
    picked, weight = sampled_layers(sub, settings, every)
    assert weight * len(picked) == pytest.approx(len(stack))
    by_height = {round(layer.section_height, 9): layer for layer in stack}
    for layer in picked:
        same = by_height[round(layer.section_height, 9)]
        assert layer.thickness == pytest.approx(same.thickness)
        assert layer.region.symmetric_difference(same.region).area < 1e-9
    # The middle of each run of `every` layers: the T's bar and stem are both sampled.
    assert len({round(layer.region.area, 6) for layer in picked}) >= 2


def test_sampling_refuses_a_step_below_one():
    with pytest.raises(PlanError, match="every 0"):
        sampled_layers(_whole(samples.t_block(), (0.0, 0.0, 1.0)), LayerSettings(), 0)


#: The shipped margin (the tests below set others).
MARGIN = search.COARSE_MARGIN


def _choice(name: str, margin: float, monkeypatch, mirrors: bool = True):
    """The plan choice with this margin; `mirrors=False` slices both of each d, −d pair."""
    monkeypatch.setattr(search, "COARSE_MARGIN", margin)
    if not mirrors:
        monkeypatch.setattr(search, "_mirror_costed", lambda *args: False)
    shape = samples.SAMPLES[name]()
    options = PlanOptions()
    try:
        return choose_plan(shape, options, check_options(shape, options))
    finally:
        monkeypatch.undo()


@pytest.mark.slow
@pytest.mark.parametrize("name", ["t_block", "l_block"])
def test_the_coarse_ranking_chooses_what_exact_costing_chooses(name, monkeypatch):
    exact = _choice(name, float("inf"), monkeypatch, mirrors=False)   # every one exactly
    coarse_only = _choice(name, 0.0, monkeypatch)         # only the coarse best
    quick = _choice(name, MARGIN, monkeypatch)
    assert all(c.exact for c in exact.candidates)
    assert sum(c.exact for c in coarse_only.candidates) == 1
    # The T's two best orientations are within 0.2 % of each other by the balanced score:
    # the sampled estimate alone may swap them; the margin sends both to exact costing.
    assert quick.candidates[0].label == exact.candidates[0].label
    assert quick.candidates[0].exact
    assert quick.candidates[0].cost.seconds == pytest.approx(exact.candidates[0].cost.seconds,
                                                             rel=1e-9)
    exact_cost = {c.label: c.cost for c in exact.candidates}
    for c in coarse_only.candidates:
        # The sample's estimate: within 5 % of the exact cost (3.3 % at worst on the wedge).
        assert c.cost.seconds == pytest.approx(exact_cost[c.label].seconds, rel=0.05)
        assert c.cost.material == pytest.approx(exact_cost[c.label].material, rel=0.05)
    # Coarse estimates never outrank an exact cost, and say what they are.
    flags = [c.exact for c in quick.candidates]
    assert flags == sorted(flags, reverse=True)
    assert {row["estimate"] for row in (c.row() for c in quick.candidates)} <= {
        "layers", f"every {search.ordinal(search.COARSE_EVERY)} layer"}


def test_a_coarse_candidate_with_more_overhang_than_an_exact_one_is_not_sliced(monkeypatch):
    """Residual overhang ranks first: a coarse candidate that leaves more of it than an
    exact one cannot win, so its layers are not cut (the bottle's whole orientation was,
    3 s of its plan choice); with no exact candidate the best coarse one still is."""
    from types import SimpleNamespace

    from freecad_conformal.paths.cost import PlanCost

    def candidate(label: str, overhang: float, exact: bool) -> search.Candidate:
        return search.Candidate(label, None, SimpleNamespace(support_area=overhang), {},
                                PlanCost(100.0, 10.0, {}, 0.0), exact=exact)

    sliced: list[str] = []

    def exact(label, *args):
        sliced.append(label)
        return candidate(label, 20.0, True)

    monkeypatch.setattr(search, "_exact", exact)
    decomposed, whole = candidate("decomposed", 10.0, True), candidate("whole", 20.0, False)
    result = search._refined([decomposed, whole], None, None, None, "balanced")
    assert sliced == [] and result == [decomposed, whole]
    search._refined([whole], None, None, None, "balanced")
    assert sliced == ["whole"]


@pytest.mark.parametrize("objective", ["balanced", "time"])
def test_coarse_candidates_far_behind_an_exact_one_are_not_sliced(objective, monkeypatch):
    """An exactly costed candidate (the table's decomposition) leading every coarse one of
    tied overhang by more than EXACT_LEAD is not challenged: the sampled estimate cannot be
    that far off. Within the lead the best coarse one is still sliced."""
    from types import SimpleNamespace

    from freecad_conformal.paths.cost import PlanCost

    def candidate(label: str, seconds: float, exact: bool) -> search.Candidate:
        return search.Candidate(label, None, SimpleNamespace(support_area=5.0, subparts=[]),
                                {}, PlanCost(seconds, 10.0, {}, 0.0), exact=exact)

    sliced: list[str] = []

    def exact(label, *args):
        sliced.append(label)
        return candidate(label, 100.0, True)

    monkeypatch.setattr(search, "_exact", exact)
    lead = search.EXACT_LEAD
    decomposed = candidate("decomposed", 100.0, True)
    for seconds, expected in ((100.0 * (1 + lead) + 0.5, []),
                              (100.0 * (1 + lead) - 0.5, ["whole"])):
        sliced.clear()
        whole = candidate("whole", seconds, False)
        result = search._refined([decomposed, whole], None, None, None, objective)
        assert sliced == expected
        assert result[0] is decomposed and result[1].exact == bool(expected)


def test_a_whole_orientation_the_decomposition_already_built_is_not_sliced_again(
        App, Part, monkeypatch):
    """A decomposition that kept the solid whole along the same direction, laid out the
    same, is the same plan: the coarse twin takes its exact layers and cost (the screw
    thread sliced its tilted layers twice, 50 s each); a different direction is sliced."""
    from freecad_conformal.decomposition.subparts import BuildPlan
    from freecad_conformal.paths.cost import PlanCost

    def plan(direction, shift=0.0) -> BuildPlan:
        box = Part.makeBox(10, 20, 30, App.Vector(shift, 0, 0))
        return BuildPlan(subparts=[SubPart(index=0, shape=box, build_direction=np.array(direction),
                                           volume=box.Volume)], order=[0])

    decomposed = search.Candidate("decomposed", None, plan((0.0, 0.0, 1.0)), {0: ["layers"]},
                                  PlanCost(50.0, 5.0, {}, 0.0), split=True)
    sliced: list[str] = []

    def exact(label, placed, plan, *args):
        sliced.append(label)
        return search.Candidate(label, placed, plan, {0: []}, PlanCost(60.0, 6.0, {}, 0.0))

    monkeypatch.setattr(search, "_exact", exact)
    for direction, shift, expected in (((0.0, 0.0, 1.0), 0.0, []),
                                       ((0.0, 1.0, 0.0), 0.0, ["whole"]),
                                       ((0.0, 0.0, 1.0), 1e-3, ["whole"])):
        sliced.clear()
        whole = search.Candidate("whole", None, plan(direction, shift), {},
                                 PlanCost(49.0, 5.0, {}, 0.0), exact=False)
        result = search._refined([decomposed, whole], None, None, None, "balanced")
        assert sliced == expected
        assert result[1].exact and result[1].label == "whole"
        if not expected:
            assert result[1].layers is decomposed.layers and result[1].cost is decomposed.cost


def test_the_decompositions_own_build_is_not_costed_again(Part, monkeypatch):
    """A sphere's decomposition makes no cut and builds it along its best direction, the
    direction the whole-part candidate then takes: that candidate is the same build and
    takes its layers and cost at once, without a coarse slicing (the connecting rod sliced
    its 320 layers twice, 7 s each)."""
    def refuse(*args, **kwargs):
        raise AssertionError("the twin was sliced again")

    monkeypatch.setattr(search, "sampled_layers", refuse)
    sphere = Part.makeSphere(10.0)
    options = PlanOptions()
    choice = choose_plan(sphere, options, check_options(sphere, options, None))
    labels = [c.label for c in choice.candidates]
    assert "decomposed" in labels and any(label.startswith("whole along") for label in labels)
    first, second = choice.candidates
    assert first.exact and second.exact and first.layers is second.layers


def test_a_coarse_candidate_reports_its_sub_parts(App, Part):
    """A coarsely costed candidate keeps no layers; its report row still counts the
    sub-parts it builds (the wedge's summary read 0 for the orientations it did not slice)."""
    from freecad_conformal.decomposition.subparts import BuildPlan
    from freecad_conformal.paths.cost import PlanCost

    box = Part.makeBox(10, 20, 30)
    plan = BuildPlan(subparts=[SubPart(index=0, shape=box, build_direction=np.array([0.0, 0.0, 1.0]),
                                       volume=box.Volume)], order=[0])
    coarse = search.Candidate("whole along (+0, +1, +0)", None, plan, {}, PlanCost(5.0, 1.0, {}, 0.0),
                              exact=False)
    assert coarse.sub_parts == 1 and coarse.row()["sub_parts"] == 1
    empty = search.Candidate("sliced", None, plan, {0: []}, PlanCost(5.0, 1.0, {}, 0.0))
    assert empty.sub_parts == 0     # sliced, and thinner than a layer: nothing built


def test_of_two_mirrored_whole_builds_only_the_better_sampled_one_is_sliced(monkeypatch):
    """Built along d and −d a solid is cut by the same planes: the better sampled of the
    two is costed exactly and the other keeps its sampled cost, ranked behind (the gear's
    ±Z took 0.7 s of its 1.2 s choice). Should the better one not slice, its mirror is
    sliced instead; an orientation that is no mirror is sliced as before."""
    from types import SimpleNamespace

    from freecad_conformal.paths.cost import PlanCost

    def candidate(direction, seconds: float, exact: bool = False) -> search.Candidate:
        return search.Candidate(f"whole along {direction}", None,
                                SimpleNamespace(support_area=0.0, subparts=[]), {},
                                PlanCost(seconds, 10.0, {}, 0.0), exact=exact,
                                direction=direction)

    sliced: list[str] = []
    unsliceable: set[str] = set()

    def exact(label, *args):
        sliced.append(label)
        if label in unsliceable:
            raise search.GeometryError(f"{label} cannot be cut")
        return search.Candidate(label, None, SimpleNamespace(support_area=0.0, subparts=[]),
                                {0: ["layer"]}, PlanCost(100.0, 10.0, {}, 0.0))

    monkeypatch.setattr(search, "_exact", exact)
    up, down, side = (0.0, 0.0, 1.0), (-0.0, -0.0, -1.0), (1.0, 0.0, 0.0)
    candidates = [candidate(up, 100.2), candidate(down, 100.0), candidate(side, 100.5)]
    result = search._refined(candidates, None, None, None, "balanced")
    assert sliced == [f"whole along {down}", f"whole along {side}"]
    by_direction = {c.direction: c for c in result}
    assert not by_direction[up].exact and by_direction[down].exact and by_direction[side].exact
    assert search.ranked(result, "balanced")[-1].direction == up
    # The one left sampled names the one sliced, for the summary to say why.
    assert by_direction[up].mirror_of == f"whole along {down}"
    assert by_direction[up].row()["mirror_of"] == f"whole along {down}"
    assert by_direction[down].mirror_of is None and by_direction[side].mirror_of is None

    sliced.clear()
    unsliceable.add(f"whole along {down}")
    result = search._refined(candidates, None, None, None, "balanced")
    assert sliced == [f"whole along {down}", f"whole along {up}", f"whole along {side}"]
    assert [c.direction for c in result if c.exact] == [up, side]
    assert all(c.mirror_of is None for c in result)


def test_the_summary_says_what_each_plans_figures_come_from():
    """The arch's summary showed its chosen build's planned figures beside its mirror's
    sampled ones, lower by the estimate's error, under one header: the mirror looked
    cheaper than the plan chosen. Each row now says what its figures are, and a mirror
    says why it was not sliced."""
    from types import SimpleNamespace

    from freecad_conformal.jobs.report import _candidate_lines
    from freecad_conformal.paths.cost import PlanCost

    def row(label, seconds, material, exact=True, mirror_of=None, **given):
        return search.Candidate(label, None, SimpleNamespace(support_area=0.0, subparts=[]),
                                {}, PlanCost(seconds, material, {}, 0.0), exact=exact,
                                mirror_of=mirror_of).row(**given)

    chosen = row("whole along (+0, -1, +0)", 0.0, 0.0, chosen=True, figures=(4447.0, 14200.0))
    mirror = row("whole along (+0, +1, +0)", 4408.0, 14178.0, exact=False,
                 mirror_of="whole along (+0, -1, +0)")
    sampled = row("whole along (+0, +0, -1)", 4977.0, 14532.0, exact=False)
    sliced = row("decomposed", 5000.0, 15000.0)

    def table(rows: list[dict]) -> tuple[dict[str, str], list[str]]:
        lines = _candidate_lines(SimpleNamespace(candidates=rows, objective="balanced"))
        start = next(k for k, line in enumerate(lines) if line.strip().startswith("plan "))
        end = next(k for k, line in enumerate(lines) if line.strip().startswith("figures:"))
        cells = [re.split(r" {2,}", line[3:].strip()) for line in lines[start + 1:end]]
        return {row[0]: row[-1] for row in cells}, lines

    refined = row("whole along (+0.158, -0.254, -0.954)", 4977.0, 14532.0, exact=False)
    shown, _ = table([chosen, refined])      # a refined direction's label, whole
    assert shown == {"whole along (+0, -1, +0)": "planned",
                     "whole along (+0.158, -0.254, -0.954)": "sampled"}
    shown, lines = table([chosen, mirror, sliced])
    assert shown == {"whole along (+0, -1, +0)": "planned", "whole along (+0, +1, +0)": "mirrored",
                     "decomposed": "sliced"}
    legend = next(line for line in lines if line.strip().startswith("figures:"))
    assert all(f"{kind} = " in legend for kind in shown.values()) and "sampled =" not in legend
    [why] = [line for line in lines if "built from the other end" in line]
    assert why.strip().startswith("whole along (+0, +1, +0) is whole along (+0, -1, +0)")
    shown, lines = table([chosen, sampled])
    assert shown == {"whole along (+0, -1, +0)": "planned", "whole along (+0, +0, -1)": "sampled"}
    assert any(f"sampled = from every {search.ordinal(search.COARSE_EVERY)} layer" in line
               for line in lines)
    assert [search.ordinal(n) for n in (1, 2, 3, 4, 11, 12, 13, 21, 22, 103, 111)] == [
        "1st", "2nd", "3rd", "4th", "11th", "12th", "13th", "21st", "22nd", "103rd", "111th"]
    assert not any("other end" in line or "mirrored" in line for line in lines)


@pytest.mark.slow
def test_a_nozzle_standing_on_either_end_is_sliced_once_and_chosen_as_before(monkeypatch):
    """The nozzle stands on either end: one of ±Z is sliced, and it is the one exact
    costing of both would choose."""
    shape = samples.nozzle()
    options = PlanOptions()
    quick = choose_plan(shape, options, check_options(shape, options))
    exact_flags = {c.direction: c.exact for c in quick.candidates if c.direction is not None}
    assert exact_flags[(0.0, 0.0, 1.0)] != exact_flags[(0.0, 0.0, -1.0)]
    monkeypatch.setattr(search, "_mirror_costed", lambda *args: False)
    both = choose_plan(shape, options, check_options(shape, options))
    assert all(both.candidates[k].exact for k in range(2))
    assert quick.candidates[0].label == both.candidates[0].label
