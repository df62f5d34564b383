"""The plan's cost before paths (paths/cost.py) and the choice among candidate plans
(jobs/search.py): the estimate agrees with the full plan, and the cheapest plan with the
least residual overhang is the one built."""
from __future__ import annotations

import dataclasses
import json
from types import SimpleNamespace

import numpy as np
import pytest
import shapely
from shapely.geometry import MultiPolygon, Polygon

from freecad_conformal.errors import PlanError
from freecad_conformal.geometry import samples
from freecad_conformal.geometry.solids import load_shape
from freecad_conformal.jobs.options import plan_options
from freecad_conformal.jobs.placement import turn_up
from freecad_conformal.jobs.job import plan_job
from freecad_conformal.jobs.plan import PlanOptions, check_options, single_plan
from freecad_conformal.jobs.search import OVERHANG_TIE, ranked
from freecad_conformal.geometry.frames import LayerFrame
from freecad_conformal.layers.model import Layer, LayerSettings
from freecad_conformal.layers.plan import plan_layers
from freecad_conformal.paths.cost import CALIBRATION_GOAL, Motion, plan_cost
from freecad_conformal.paths.map3d import skin_regions

SAMPLE_PARTS = ("bracket", "jack", "hinge", "l_block", "t_block", "inclined_rod")
SHARED_PARTS = ("CrankArm.brep", "MODERN_Table_1.brep", "Pump_Nut.brep", "bottle.brep",
                "revolved_sphere.step", "screw.step", "sliced_cylinder.step", "wedge_ok.brep")


def _option(name: str, seconds: float, material: float, overhang: float = 0.0,
            exact: bool = True):
    return SimpleNamespace(label=name, overhang=overhang, exact=exact,
                           cost=SimpleNamespace(seconds=seconds, material=material))


def test_ranking_puts_least_overhang_first_then_the_objective():
    fast = _option("fast", 100.0, 30.0)
    lean = _option("lean", 150.0, 10.0)
    even = _option("even", 110.0, 12.0)
    supported = _option("supported", 10.0, 1.0, overhang=50.0)
    nearly = _option("nearly", 105.0, 11.0, overhang=0.5 * OVERHANG_TIE)
    options = [supported, fast, lean, even, nearly]
    assert ranked(options, "time")[0] is fast
    assert ranked(options, "material")[0] is lean
    # balanced: 110/100 + 12/10 = 2.3 beats fast's 1 + 3 = 4 and lean's 1.5 + 1 = 2.5;
    # `nearly` (1.05 + 1.1 = 2.15) is within the overhang tie, so it wins.
    assert [c.label for c in ranked(options, "balanced")][:3] == ["nearly", "even", "lean"]
    assert ranked(options, "time")[-1] is supported
    # A coarse estimate (sampled layers) never outranks an exact cost, however cheap it looks.
    sampled = _option("sampled", 50.0, 5.0, exact=False)
    assert [c.label for c in ranked(options + [sampled], "time")] == [
        "fast", "nearly", "even", "lean", "sampled", "supported"]
    with pytest.raises(PlanError, match="objective must be one of .*'fastest'"):
        ranked(options, "fastest")


def test_the_objective_is_a_checked_plan_setting():
    assert plan_options({"objective": "material"}).objective == "material"
    assert plan_options({}).objective == "balanced"
    with pytest.raises(Exception, match="objective"):
        plan_options({"objective": "cheap"})


def test_skins_follow_the_regions_not_only_identical_neighbours(Part, App):
    """A 20 mm square with a 10 mm square on top: skins at the bed, under the step (where
    the layer above is smaller, not the same) and at the top; none in between."""
    base = Part.makeBox(20, 20, 4)
    top = Part.makeBox(10, 10, 4, App.Vector(5, 5, 4))
    sub = single_plan(base.fuse(top).removeSplitter()).subparts[0]
    layers = plan_layers(sub, LayerSettings(thickness=0.5))
    skins = skin_regions(layers, 2, 2, rests_on_parent=False)
    areas = [round(s.area, 3) for s in skins]
    assert len(areas) == 16
    assert areas[:2] == [400.0, 400.0]            # bottom skin
    assert areas[2:6] == [0.0] * 4                # inside the base
    assert areas[6:8] == [300.0, 300.0]           # under the step: the ring around the top
    assert areas[8:14] == [0.0] * 6               # inside the top block
    assert areas[14:] == [100.0, 100.0]           # top skin
    # Resting on its parent, the first layers have no bottom skin.
    assert skin_regions(layers, 2, 2, rests_on_parent=True)[0].area == 0.0


def _flat_layer(index: int, region) -> Layer:
    frame = LayerFrame.for_direction((0.0, 0.0, 1.0))
    return Layer(subpart=0, index=index, frame=frame, section_height=0.1 + 0.2 * index,
                 region=region, top_point=np.array([0.0, 0.0, 0.2 * (index + 1)]),
                 top_normal=np.array([0.0, 0.0, 1.0]), thickness_min=0.2, thickness_max=0.2)


def test_an_invalid_section_is_repaired_not_fatal_to_the_skins():
    """A Boolean fallback's section can touch itself (the bottle along X); GEOS refuses
    to intersect it, so the skins repair it instead of failing the whole plan."""
    square = MultiPolygon([Polygon([(0, 0), (10, 0), (10, 10), (0, 10)])])
    bow_tie = MultiPolygon([Polygon([(0, 0), (10, 10), (10, 0), (0, 10)])])
    assert not bow_tie.is_valid
    layers = [_flat_layer(k, region) for k, region in enumerate([square, bow_tie, square])]
    with pytest.raises(shapely.errors.GEOSException):
        square.intersection(bow_tie)                  # what GEOS does with it
    skins = skin_regions(layers, 1, 0, rests_on_parent=False)
    # The repaired bow tie is two triangles, half the square: the rest of the square
    # beneath it is top skin; the bow tie is covered by the square above it.
    assert [round(s.area, 6) for s in skins] == [50.0, 0.0, 100.0]


def test_single_plan_reports_the_overhang_it_leaves():
    t_block = samples.t_block()
    up = single_plan(t_block)
    down = single_plan(t_block, (0.0, 0.0, -1.0))
    assert up.support_area > 10.0
    assert down.support_area == 0.0
    assert up.support_area_single_direction == up.support_area


def test_a_plan_built_whole_names_its_solids_as_the_notes_count_them(Part, App):
    # The notes say "solid 1" of a part's first solid (layout, roots): the summary's
    # sub-part named "solid 0" beside them read as another solid.
    first, second = Part.makeBox(10, 10, 10), Part.makeBox(10, 10, 10, App.Vector(20, 0, 0))
    plan = single_plan(Part.makeCompound([first, second]))
    assert [sub.name for sub in plan.subparts] == ["solid 1", "solid 2"]
    assert [sub.solid_index for sub in plan.subparts] == [0, 1]


def test_a_direction_of_the_part_as_given_turns_with_the_placement():
    _, placement = turn_up(samples.jack(), (1.0, 0.0, 0.0))
    np.testing.assert_allclose(placement.rotate((1.0, 0.0, 0.0)), (0.0, 0.0, 1.0), atol=1e-12)
    _, still = turn_up(samples.jack(), (0.0, 0.0, 1.0))
    np.testing.assert_allclose(still.rotate((0.3, 0.4, 0.5)), (0.3, 0.4, 0.5))


@pytest.mark.slow
@pytest.mark.parametrize("objective,key", [("time", "time_s"), ("material", "material_mm3")])
def test_the_t_is_built_whole_in_its_cheapest_support_free_orientation(objective, key):
    """The T prints support-free upside down and on its side (a planar slicer turns it
    over): one piece, never the 3 sub-parts of the T as placed, and the orientation that is
    cheapest by the objective among those the search compared."""
    t_block = samples.t_block()
    result = plan_job(t_block, PlanOptions(objective=objective), part="t")
    rows = result.candidates
    assert len(rows) >= 2 and [r["chosen"] for r in rows].count(True) == 1
    chosen = next(r for r in rows if r["chosen"])
    assert chosen[key] == min(r[key] for r in rows)
    assert chosen["sub_parts"] == 1 and chosen["residual_overhang_mm2"] == 0.0
    assert len(result.subparts) == 1 and result.plan.support_area == 0.0
    # The estimate the choice was made on is the plan's own within the calibration goal.
    assert chosen["time_s"] == pytest.approx(result.time_s, rel=CALIBRATION_GOAL)
    assert chosen["material_mm3"] == pytest.approx(result.material_volume, rel=CALIBRATION_GOAL)
    report = json.loads(json.dumps(result.report()))
    assert report["objective"] == objective and report["candidates"] == rows
    summary = result.summary()
    builds = [r for r in rows if r["same_build_as"] is None]
    assert f"plans compared: {len(builds)}" in summary and chosen["label"] in summary


def test_a_decomposition_without_a_cut_and_its_whole_twin_are_one_plan_in_the_summary(Part):
    """A sphere's decomposition makes no cut: it is the whole build along its best
    direction, the other candidate. The summary listed both, alike, as two plans compared,
    the first called decomposed; the report marks the twin, the summary shows no choice."""
    result = plan_job(Part.makeSphere(10.0), plan_options({}), part="ball")
    first, second = result.candidates
    assert first["chosen"] and first["same_build_as"] is None
    assert second["label"].startswith("whole along") and second["same_build_as"] == first["label"]
    assert (second["time_s"], second["material_mm3"]) == (first["time_s"], first["material_mm3"])
    summary = result.summary()
    assert "plans compared" not in summary and "chosen among" not in summary
    assert json.loads(json.dumps(result.report()))["candidates"][1]["same_build_as"] == "decomposed"


def test_a_lone_candidate_is_not_costed_and_reports_the_plans_own_figures(monkeypatch):
    """The search compares nothing when it is left with one plan (the domed cylinder stands
    support-free on its base only; the bottle's decomposition: 1.0 s of its choice): its
    cost is not estimated, and its row carries the built plan's time and material."""
    from freecad_conformal.jobs import search

    costed: list[str] = []
    real = search.plan_cost
    monkeypatch.setattr(search, "plan_cost", lambda *args: costed.append("cost") or real(*args))
    result = plan_job(samples.domed_cylinder(), plan_options({}), part="dome")
    assert costed == []
    [row] = result.candidates
    assert row["chosen"] and row["estimate"] == "plan"
    assert row["time_s"] == result.time_s and row["material_mm3"] == result.material_volume
    assert "plans compared" not in result.summary()


def test_twin_candidates_compare_nothing():
    """Candidates sharing one cost (the same build: `_as_twin`) keep their order and their
    cost is not read; two costs are ranked."""
    from freecad_conformal.jobs import search

    class Unread:
        def __getattr__(self, name):
            raise AssertionError(f"the cost was read ({name})")

    shared = Unread()
    twins = [search.Candidate(label, None, SimpleNamespace(support_area=1.0), {}, shared)
             for label in ("decomposed", "whole along (+0, +1, +0)")]
    assert not search.compared(twins) and search.ranked(twins, "balanced") == twins
    cheaper = _option("cheaper", 50.0, 5.0, overhang=1.0)
    assert search.compared(twins[:1] + [cheaper])


def test_the_one_exact_plan_of_least_overhang_wins_without_its_cost_being_read():
    """A coarse estimate never outranks an exact cost: the one exactly costed candidate of
    least overhang wins unread (CostWhenRead), the others are ranked among themselves; two
    exact ones are compared by their costs."""
    from freecad_conformal.jobs import search

    class Unread(search.CostWhenRead):
        def __init__(self):
            super().__init__(None, {}, None, None)

        def __getattr__(self, name):
            raise AssertionError(f"the cost was read ({name})")

    def coarse(label, seconds, overhang=0.0):
        option = _option(label, seconds, 10.0, overhang, exact=False)
        option.costed = True
        return option

    refined = search.Candidate("refined", None, SimpleNamespace(support_area=0.0), {}, Unread())
    assert not refined.costed
    slow, fast, steep = coarse("slow", 90.0), coarse("fast", 60.0), coarse("steep", 10.0, 5.0)
    order = search.ranked([slow, steep, refined, fast], "balanced")
    assert [c.label for c in order] == ["refined", "fast", "slow", "steep"]
    other = _option("other exact", 80.0, 10.0)
    other.costed = True
    with pytest.raises(AssertionError, match="the cost was read"):
        search.ranked([slow, refined, other], "balanced")


@pytest.mark.slow
def test_a_root_given_is_kept_without_a_search():
    result = plan_job(samples.t_block(), PlanOptions(root=(0.0, 0.0, 1.0)), part="t")
    assert result.candidates == [] and "plans compared" not in result.summary()


def _check_calibrated(shape, name: str) -> None:
    """The estimate of the plan that was built, against that plan's own time and material."""
    options = plan_options({})
    path_settings = check_options(shape, options)[3]
    result = plan_job(shape, options, part=name)
    cost = plan_cost(result.plan, result.layers, path_settings, Motion.of(result.machine, options.jerk))
    assert cost.seconds == pytest.approx(result.time_s, rel=CALIBRATION_GOAL), name
    assert cost.material == pytest.approx(result.material_volume, rel=CALIBRATION_GOAL), name


@pytest.mark.slow
@pytest.mark.parametrize("name", SAMPLE_PARTS)
def test_the_cost_is_calibrated_on_the_samples(name):
    _check_calibrated(samples.SAMPLES[name](), name)


@pytest.mark.slow
@pytest.mark.parametrize("name", SHARED_PARTS)
def test_the_cost_is_calibrated_on_the_real_parts(parts_dir, name):
    _check_calibrated(load_shape(parts_dir / name), name)


def test_a_box_with_walls_thinner_than_a_bead_gets_them_and_its_cost_counts_them(App, Part):
    """A 20 mm box with 0.3 mm walls under a 0.4 mm bead: no perimeter fits the walls, and
    they were left out (0.16 of its 0.42 cm³ deposited, silently). Each wall layer now gets
    one bead along the wall's middle, and the estimate the choice reads counts it too."""
    box = Part.makeBox(20, 20, 10).cut(Part.makeBox(19.4, 19.4, 10, App.Vector(0.3, 0.3, 0.5)))
    _check_calibrated(box, "thin box")
    result = plan_job(box, plan_options({}), part="thin box")
    assert result.material_volume > 0.85 * box.Volume
    walls = [path for path in result.assembly.paths
             if path.closed and path.width == pytest.approx(0.34)]
    assert len(walls) >= 45                  # one per layer of wall above the 0.5 mm floor


@pytest.mark.slow
def test_a_decomposition_that_cannot_be_built_gives_way_to_the_whole_part(monkeypatch):
    """No support-free orientation, and the decomposition fails (as with no collision-free
    order): the part built whole along its best single direction is still a plan, and its
    notes say why, instead of no plan at all."""
    from freecad_conformal.geometry.overhang import DEFAULT_OVERHANG_ANGLE
    from freecad_conformal.jobs.plan import machine_plan
    from freecad_conformal.jobs.search import plan_candidates

    jack = samples.jack()
    options = plan_options({})
    checked = check_options(jack, options)

    def make_plan(root, split):
        if split:
            raise PlanError("no collision-free build order for 6 sub-parts: P2 would hit P1")
        return machine_plan(jack, PlanOptions(root=root, decompose=False))

    from freecad_conformal.jobs import search

    sampled: list[str] = []
    costed = search.coarse_candidate
    monkeypatch.setattr(search, "coarse_candidate",
                        lambda label, *args: sampled.append(label) or costed(label, *args))
    found = plan_candidates(jack, make_plan, options.layers, checked[3],
                            Motion.of(checked[4], options.jerk), DEFAULT_OVERHANG_ANGLE)
    assert [c.label.split(" (")[0] for c in found] == ["whole along"]
    # The only candidate left is sliced once, on its layers, not first on a sample.
    assert found[0].exact and sampled == []
    # and the summary does not say that no cut was found
    from freecad_conformal.decomposition.subparts import WHOLE_AFTER_FAILURE
    from freecad_conformal.jobs.report import overhang_reason, support_text

    assert found[0].plan.support_reason == WHOLE_AFTER_FAILURE
    assert overhang_reason(found[0].plan) == WHOLE_AFTER_FAILURE     # the report's too
    said = support_text(found[0].plan, tilted=False, hybrid=False)
    assert WHOLE_AFTER_FAILURE in said and "no cut found" not in said
    assert found[0].overhang > 100.0 and found[0].sub_parts == 1
    assert any("no decomposition could be built (no collision-free build order" in note
               for note in found[0].plan.notes)


def test_bridges_are_the_first_solid_layer_over_sparse_infill():
    """Eight 20 mm squares, the top three solid: only the first of those (over the sparse
    fourth layer) is a bridge; a sparse piece under `solid_below_area` carries none."""
    from freecad_conformal.paths.map3d import bridge_regions

    square = MultiPolygon([Polygon([(0, 0), (20, 0), (20, 20), (0, 20)])])
    layers = [_flat_layer(k, square) for k in range(8)]
    skins = skin_regions(layers, 3, 0, rests_on_parent=True)
    assert [round(s.area) for s in skins] == [0, 0, 0, 0, 0, 400, 400, 400]
    bridges = bridge_regions(layers, skins, solid_below_area=70.0)
    assert [round(b.area) for b in bridges] == [0, 0, 0, 0, 0, 400, 0, 0]
    assert all(b.area == 0 for b in bridge_regions(layers, skins, solid_below_area=500.0))


def test_a_skin_over_nothing_is_a_bridge_and_a_slope_is_not():
    """A slot's ceiling (walls below, nothing between them) is a bridge, whatever the
    speeds; the steps of a wall leaning within the overhang angle (0.2 mm a layer) are
    not, nor is anything without a bead width to measure it by."""
    from freecad_conformal.paths.map3d import AIR_MIN_WIDTHS, air_at, bridge_regions

    block = Polygon([(0, 0), (40, 0), (40, 20), (0, 20)])
    slot = Polygon([(5, 6), (35, 6), (35, 14), (5, 14)])
    layers = [_flat_layer(k, MultiPolygon([block.difference(slot) if k < 4 else block]))
              for k in range(7)]
    skins = skin_regions(layers, 3, 3, rests_on_parent=False)
    bridges = bridge_regions(layers, skins, solid_below_area=float("inf"), bead_width=0.4)
    assert [round(b.area, 6) for b in bridges] == [0, 0, 0, 0, 240.0, 0, 0]
    assert bridges[4].equals(MultiPolygon([slot]))
    assert air_at(layers, 4, bridges[4], 0.4).equals(MultiPolygon([slot]))
    assert air_at(layers, 5, bridges[5], 0.4) is None
    assert all(b.is_empty for b in bridge_regions(layers, skins, float("inf")))
    leaning = [_flat_layer(k, MultiPolygon([Polygon([(0.2 * k, 0), (20 + 0.2 * k, 0),
                                                     (20 + 0.2 * k, 20), (0.2 * k, 20)])]))
               for k in range(8)]
    leaning_skins = skin_regions(leaning, 3, 3, rests_on_parent=False)
    assert all(b.is_empty for b in bridge_regions(leaning, leaning_skins, float("inf"), 0.4))
    # a step just wide enough is a bridge
    step = AIR_MIN_WIDTHS * 0.4 + 0.01
    ledge = [_flat_layer(k, MultiPolygon([Polygon([(0, 0), (20 + (step if k >= 4 else 0), 0),
                                                   (20 + (step if k >= 4 else 0), 20),
                                                   (0, 20)])])) for k in range(8)]
    ledge_bridges = bridge_regions(ledge, skin_regions(ledge, 3, 3, False), float("inf"), 0.4)
    assert ledge_bridges[4].area == pytest.approx(step * 20.0)


def test_a_bridge_over_nothing_is_laid_across_its_shortest_span():
    """Where the fewest-turns direction lays the slot's ceiling in 30 mm lines over the
    void, each line anchored at its ends only, the bridge over nothing runs across the
    8 mm between its walls, on every layer."""
    from freecad_conformal.paths.fill2d import FillSettings, fill_layer

    block = MultiPolygon([Polygon([(0, 0), (40, 0), (40, 20), (0, 20)])])
    slot = MultiPolygon([Polygon([(5, 6), (35, 6), (35, 14), (5, 14)])])
    settings = FillSettings(bead_width=0.4)

    def rows(air, layer_index=0):
        paths = [p for p in fill_layer(block, settings, layer_index, solid=block, height=0.2,
                                       bridge=slot, air=air) if p.role == "bridge_infill"]
        assert paths
        steps = np.concatenate([np.diff(p.points, axis=0) for p in paths])
        lengths = np.linalg.norm(steps, axis=1)
        return lengths[lengths > 1.0]          # the rows, not the links between them

    assert rows(None).max() > 25.0                              # along the slot
    for layer_index in (0, 1):                                  # no alternation
        across = rows(slot, layer_index)
        assert across.max() < 8.0 and len(across) > 50


def test_speeds_are_plan_settings_and_bridges_fill_apart_only_at_their_own_speed():
    default = plan_options({})
    assert default.paths.feeds.for_role("bridge_infill") == default.paths.feeds.solid_infill
    assert not default.paths.feeds.bridges_apart
    given = plan_options({"bridge_infill_speed": 60.0, "solid_infill_speed": 20.0,
                          "infill_speed": 80.0, "external_perimeter_speed": 30.0, "jerk": 8.0})
    assert given.paths.feeds.bridge_infill == 3600.0 and given.paths.feeds.solid_infill == 1200.0
    assert given.paths.feeds.infill == 4800.0 and given.paths.feeds.external_perimeter == 1800.0
    assert given.paths.feeds.bridges_apart and given.jerk == 8.0
    with pytest.raises(Exception, match="bridge infill speed"):
        plan_options({"bridge_infill_speed": 0.0})


@pytest.mark.slow
def test_bridge_infill_at_its_speed_shortens_the_t_and_the_cost_sees_it():
    """The T upside down has solid skins over its sparse bar: at 60 mm/s instead of the
    solid 20 the bridges save time; the cost estimate follows the plan within its goal."""
    values = {"root": (0.0, 0.0, -1.0), "solid_infill_speed": 20.0}
    slow = plan_job(samples.t_block(), plan_options(values), part="t")
    fast = plan_job(samples.t_block(), plan_options({**values, "bridge_infill_speed": 60.0}),
                    part="t")
    roles = {p.role for p in fast.assembly.paths}
    assert "bridge_infill" in roles and "bridge_infill" not in {p.role for p in slow.assembly.paths}
    assert fast.time_s < slow.time_s - 30.0
    assert fast.material_volume == pytest.approx(slow.material_volume, rel=0.01)
    options = plan_options({**values, "bridge_infill_speed": 60.0})
    checked = check_options(samples.t_block(), options)
    cost = plan_cost(fast.plan, fast.layers, checked[3], Motion.of(checked[4], options.jerk))
    assert cost.seconds == pytest.approx(fast.time_s, rel=CALIBRATION_GOAL)


@pytest.mark.slow
def test_a_decomposition_occ_cannot_slice_gives_way_to_the_whole_part(monkeypatch):
    """A sub-part whose section OCC cannot cut (the bottle's decomposition on OCCT 7.8)
    loses that candidate, not the plan: the solid is built whole, and the notes say why."""
    from freecad_conformal.errors import GeometryError
    from freecad_conformal.geometry.overhang import DEFAULT_OVERHANG_ANGLE
    from freecad_conformal.jobs import search
    from freecad_conformal.jobs.plan import machine_plan

    jack = samples.jack()
    options = plan_options({})
    checked = check_options(jack, options)
    real = search.plan_layers

    def failing(sub, settings):
        if sub.rule != "root":
            raise GeometryError("the section at height 24.4 mm came back empty")
        return real(sub, settings)

    monkeypatch.setattr(search, "plan_layers", failing)

    def make_plan(root, split):
        return machine_plan(jack, PlanOptions(root=root, decompose=split))

    found = search.plan_candidates(jack, make_plan, options.layers, checked[3],
                                   Motion.of(checked[4], options.jerk), DEFAULT_OVERHANG_ANGLE)
    assert [c.sub_parts for c in found] == [1] and found[0].exact
    assert any("the decomposition could not be sliced (the section at height 24.4 mm" in note
               for note in found[0].plan.notes)


def test_repeated_layers_are_costed_once_and_cost_the_same(monkeypatch):
    """A prism's layers repeat: each distinct layer (region, solid areas, thickness, infill
    direction's parity, to rounding: `stack_fill.fill_key`) is costed once, and every
    layer's cost equals its own costing (to rounding: its thickness is a difference of
    levels)."""
    from freecad_conformal.paths import cost as cost_module
    from freecad_conformal.paths.assemble import solid_areas
    from freecad_conformal.paths.map3d import air_at

    plan = single_plan(samples.t_block())
    sub = plan.subparts[0]
    layers = plan_layers(sub, LayerSettings())
    options = plan_options({})
    checked = check_options(samples.t_block(), options, None)
    settings, motion = checked[3], Motion.of(checked[4], options.jerk)
    calls = []
    original = cost_module.layer_cost

    def counted(layer, *args, **kwargs):
        calls.append(layer.index)
        return original(layer, *args, **kwargs)

    monkeypatch.setattr(cost_module, "layer_cost", counted)
    memo = cost_module.subpart_cost(sub.index, layers, settings, motion, False)
    assert len(calls) < len(layers) // 4
    skins, bridges = solid_areas(layers, settings, False)
    each = [original(layer, skin, settings, motion, bridge,
                     air_at(layers, i, bridge, settings.fill.bead_width))
            for i, (layer, skin, bridge) in enumerate(zip(layers, skins, bridges))]
    assert [c.level for c in memo.layers] == [c.level for c in each]
    assert all(dataclasses.astuple(a) == pytest.approx(dataclasses.astuple(b), rel=1e-12)
               for a, b in zip(memo.layers, each))


def test_repeated_layers_are_filled_once_and_give_the_same_paths(monkeypatch):
    """The paths of a prism's repeated layers come from one fill per distinct layer (the
    fill does not depend on the nozzle's start; only its order does), and are the paths
    each layer's own fill gives from where the last layer ended, in order (to rounding)."""
    from freecad_conformal.paths import assemble, stack_fill
    from tests.geometry.own_fills import assert_each_layers_own_fill

    plan = single_plan(samples.t_block())
    sub = plan.subparts[0]
    layers = plan_layers(sub, LayerSettings())
    # Seams nearest the nozzle: each layer's paths depend on where the last one ended.
    settings = check_options(samples.t_block(), plan_options({"seam": "nearest"}), None)[3]
    calls = []
    original = stack_fill.layer_fill

    def counted(*args, **kwargs):
        calls.append(1)
        return original(*args, **kwargs)

    monkeypatch.setattr(stack_fill, "layer_fill", counted)
    start = np.array([0.0, 0.0, 0.0])
    memo = assemble.plan_paths(layers, settings, False, start)
    assert len(calls) < len(layers) // 4
    skins, bridges = assemble.solid_areas(layers, settings, False)
    # To rounding: a layer takes the fill of one the same but for its levels' rounding.
    assert_each_layers_own_fill(layers, skins, bridges, memo, settings, start, atol=1e-9)


@pytest.mark.parametrize("whole_overhang, made", [(800.0, False), (500.5, True)])
def test_a_whole_build_leaving_more_overhang_is_not_costed(monkeypatch, whole_overhang, made):
    """The decomposition leaves 500 mm² of overhang: the part built whole along its best
    direction is a candidate only if it leaves no more (within OVERHANG_TIE), since
    overhang is ranked first; otherwise a note says what it would leave, and it is neither
    laid out nor costed (the bottle: 2.1 s of its 5.1 s choice)."""
    from freecad_conformal.decomposition.subparts import BuildPlan, SubPart
    from freecad_conformal.jobs import search
    from freecad_conformal.paths.cost import PlanCost

    jack = samples.jack()
    decomposed = BuildPlan(subparts=[SubPart(index=0, shape=jack, build_direction=np.array(
        [0.0, 0.0, 1.0]), overhang_area=500.0)], order=[0])
    asked: list[tuple] = []

    def make_plan(root, split):
        asked.append((root, split))
        return None, decomposed if split else BuildPlan(subparts=[SubPart(
            index=0, shape=jack, build_direction=np.array([1.0, 0.0, 0.0]),
            overhang_area=whole_overhang)], order=[0])

    def costed(label, placed, plan, *args):
        return search.Candidate(label, placed, plan, {0: ["layer"]}, PlanCost(10.0, 1.0, {}, 0.0))

    monkeypatch.setattr(search, "_whole_directions", lambda solid, angle: [])
    monkeypatch.setattr(search, "best_single_direction",
                        lambda solid, angle, **_: (np.array([1.0, 0.0, 0.0]), whole_overhang))
    monkeypatch.setattr(search, "_exact", costed)
    monkeypatch.setattr(search, "coarse_candidate", costed)
    found = search.plan_candidates(jack, make_plan, None, None, None, 0.7)
    assert [split for _, split in asked] == ([True, False] if made else [True])
    noted = [n for n in decomposed.notes if "not costed" in n]
    assert noted == ([] if made else ["whole along (+1, +0, +0): the part built whole would "
                                      "leave 800.0 mm² of overhang, more than 500.0: not costed"])
    assert len(found) == (2 if made else 1)


def test_a_stack_is_read_for_skins_once_for_the_cost_and_the_paths(monkeypatch):
    """The choice costs the chosen plan's stacks and the paths then fill the same layers:
    their skins are read once (the bottle's: 0.47 s twice), and again for other layers or
    other settings."""
    import dataclasses

    from freecad_conformal.paths import assemble

    plan = single_plan(samples.t_block())
    layers = plan_layers(plan.subparts[0], LayerSettings())
    settings = check_options(samples.t_block(), plan_options({}), None)[3]
    read: list[int] = []
    original = assemble.skin_regions

    def counted(stack, *args):
        read.append(len(stack))
        return original(stack, *args)

    monkeypatch.setattr(assemble, "skin_regions", counted)
    first = assemble.solid_areas(layers, settings, False)
    assert assemble.solid_areas(list(layers), settings, False) is first
    assert len(read) == 1
    thicker = dataclasses.replace(settings, top_layers=settings.top_layers + 2)
    assert assemble.solid_areas(layers, thicker, False) is not first
    assert assemble.solid_areas(layers[:-1], settings, False) is not first
    assert assemble.solid_areas(layers, settings, True) is not first
    assert len(read) == 4


def test_the_cost_says_what_cooling_added_to_each_level_and_each_move(Part):
    """What cooling-aware interleaving could win is read from these (benchmarks/
    cooling_bound.py): per level the seconds the minimum layer time added, and the seconds
    of each move between groups of sub-parts."""
    import dataclasses

    from freecad_conformal.jobs.plan import machine_plan

    pin = Part.makeCylinder(2.0, 4.0)
    options = plan_options({})
    checked = check_options(pin, options, None)
    settings, motion = checked[3], Motion.of(checked[4], options.jerk)
    plan = single_plan(pin)
    layers = {sub.index: plan_layers(sub, LayerSettings()) for sub in plan.subparts}
    cost = plan_cost(plan, layers, settings, motion)
    free = plan_cost(plan, layers, dataclasses.replace(settings, min_layer_time=0.0), motion)
    # A 4 mm pin's layers take under the 5 s minimum: every one is slowed.
    assert len(cost.cooling) == len(layers[0]) and min(cost.cooling) > 0.0
    assert cost.seconds - free.seconds == pytest.approx(sum(cost.cooling))
    assert free.cooling == [0.0] * len(layers[0]) and cost.moves == []
    _, split = machine_plan(samples.l_block(), PlanOptions(root=(0.0, 0.0, 1.0)))
    assert len(split.subparts) == 2
    layers = {sub.index: plan_layers(sub, LayerSettings()) for sub in split.subparts}
    cost = plan_cost(split, layers, settings, motion)
    assert len(cost.moves) == 1 and 0.0 < cost.moves[0] < cost.transition_seconds
