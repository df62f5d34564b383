"""Sub-parts laid in turn to cool (paths/alternate.py through paths/assemble.py), on a part
of our own making: a hub with four thin fins, each built sideways in its own direction."""
from __future__ import annotations

import dataclasses
from collections import defaultdict

import numpy as np
import pytest

from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.jobs.job import plan_job
from freecad_conformal.jobs.plan import PlanOptions
from freecad_conformal.paths import alternate
from freecad_conformal.paths.timing import move_seconds
from freecad_conformal.process.tools import Envelope
from freecad_conformal.toolpath import KINDS

MIN_LAYER_TIME = 15.0


def finned_hub():
    App, Part = import_freecad()
    V = App.Vector
    hub = Part.makeBox(14, 14, 24, V(-7, -7, 0))
    fins = [Part.makeBox(20, 3, 20, V(7, -1.5, 2)), Part.makeBox(20, 3, 20, V(-27, -1.5, 2)),
            Part.makeBox(3, 20, 20, V(-1.5, 7, 2)), Part.makeBox(3, 20, 20, V(-1.5, -27, 2))]
    return hub.fuse(fins).removeSplitter().Solids[0]


def _layer_starts(result) -> dict[int, list[float]]:
    """Per sub-part, the second each of its layers starts at, from the toolpath's timing."""
    tp = result.assembly.toolpath
    seconds, segment = move_seconds(tp, result.machine.acceleration, result.jerk)
    at = np.zeros(tp.segment_count + 1)
    np.add.at(at, segment + 1, seconds)
    start = np.cumsum(at)           # start[s]: seconds before segment s's first move
    deposits = np.flatnonzero(tp.kind == KINDS.index("deposit"))
    first: dict[tuple[int, int], float] = {}
    for path, s in zip(result.assembly.paths, deposits):
        first.setdefault((path.subpart, path.layer), float(start[s]))
    starts: dict[int, list[float]] = defaultdict(list)
    for (sub, _), when in sorted(first.items()):
        starts[sub].append(when)
    return starts


@pytest.fixture(scope="module")
def both():
    shape = finned_hub()
    options = PlanOptions()
    options.paths = dataclasses.replace(options.paths, min_layer_time=MIN_LAYER_TIME)
    turned = plan_job(shape, options, part="fins")
    options.paths = dataclasses.replace(options.paths, alternate=False)
    return turned, plan_job(shape, options, part="fins")


@pytest.mark.slow
def test_fins_are_laid_in_turn_and_the_plan_is_quicker_for_it(both):
    turned, alone = both
    assert alone.assembly.alternated == []
    fins = [sub.index for sub in turned.plan.subparts
            if abs(float(np.asarray(sub.build_direction)[2])) < 1e-6]
    assert len(fins) == 4
    assert sorted(sorted(run) for run in turned.assembly.alternated) == [sorted(fins)]
    assert any("laid in turn" in note for note in turned.plan.notes)
    # the same deposits, in another order: the same material, and much less time
    assert turned.material_volume == pytest.approx(alone.material_volume, rel=1e-9)
    assert turned.time_s < 0.75 * alone.time_s
    # every turn between fins took a checked safe move
    assert turned.assembly.moves_checked >= sum(len(turned.layers[i]) for i in fins)


@pytest.mark.slow
def test_each_fin_still_gets_the_minimum_layer_time_between_its_layers(both):
    turned, alone = both
    starts = _layer_starts(turned)
    for run in turned.assembly.alternated:
        for sub in run:
            periods = np.diff(starts[sub])
            assert len(periods) > 50
            assert periods.min() >= MIN_LAYER_TIME
    # built alone, a fin's layers were slowed down to about the minimum layer time instead
    lone = _layer_starts(alone)
    assert np.median(np.diff(lone[turned.assembly.alternated[0][0]])) == pytest.approx(
        MIN_LAYER_TIME, rel=0.15)


def test_sub_parts_built_towards_each_other_are_not_alternated():
    App, Part = import_freecad()
    V = App.Vector
    left = Part.makeBox(10, 10, 10)
    right = Part.makeBox(10, 10, 10, V(14, 0, 0))
    envelope = Envelope(tip_diameter=0.4, tip_length=2.0, body_diameter=8.0, body_length=40.0)
    # built towards each other, the tool of either reaches the other across the 4 mm gap
    assert not alternate.mutually_clear([left, right], [(1, 0, 0), (-1, 0, 0)], [[0], [1]],
                                        envelope)
    # built away from each other, neither tool comes near the other
    assert alternate.mutually_clear([left, right], [(-1, 0, 0), (1, 0, 0)], [[0], [1]], envelope)


@pytest.mark.slow
def test_a_run_whose_turns_are_not_clear_is_built_one_after_another(both, monkeypatch):
    from freecad_conformal.paths import assemble

    turned, alone = both
    monkeypatch.setattr(assemble, "_turns_clear", lambda *args: False)
    options = PlanOptions()
    options.paths = dataclasses.replace(options.paths, min_layer_time=MIN_LAYER_TIME)
    fallen = plan_job(finned_hub(), options, part="fins")
    assert fallen.assembly.alternated == []
    assert fallen.post.text == alone.post.text
