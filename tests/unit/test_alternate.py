"""The arithmetic of laying sub-parts' layers in turn to cool (paths/alternate.py)."""
from __future__ import annotations

import itertools

import numpy as np
import pytest

from freecad_conformal.paths import alternate


def test_rounds_take_one_layer_of_each_member_in_turn_until_each_runs_out():
    assert alternate.rounds([3, 1, 2]) == [(0, 0), (1, 0), (2, 0), (0, 1), (2, 1), (0, 2)]
    assert alternate.rounds([]) == []


def _periods(durations, order, switch):
    """Per step with a later layer of its member: seconds from its start to that layer's."""
    turns = [k > 0 and order[k - 1][0] != m for k, (m, _) in enumerate(order)]
    periods = []
    for k, (member, _) in enumerate(order):
        later = [j for j in range(k + 1, len(order)) if order[j][0] == member]
        if later:
            j = later[0]
            periods.append(sum(durations[k:j]) + switch * sum(turns[k + 1:j + 1]))
    return periods


@pytest.mark.parametrize("counts, switch", [([5, 5], 1.0), ([7, 2, 4], 0.5), ([3, 9], 0.0)])
def test_every_member_gets_the_minimum_layer_time_between_its_layers(counts, switch):
    rng = np.random.default_rng(sum(counts))
    order = alternate.rounds(counts)
    seconds = list(rng.uniform(0.2, 4.0, len(order)))
    durations = alternate.step_minimums(seconds, order, switch, 5.0)
    assert all(d >= s for d, s in zip(durations, seconds))
    assert min(_periods(durations, order, switch)) >= 5.0 - 1e-9
    # no layer is slowed more than its own period needs: each slowed one has a period of 5 s
    for k, (d, s) in enumerate(zip(durations, seconds)):
        if d > s + 1e-9 and any(order[j][0] == order[k][0] for j in range(k + 1, len(order))):
            own = _periods(durations[k:], order[k:], switch)[0]
            assert own == pytest.approx(5.0, abs=1e-9) or own > 5.0


def test_long_rounds_slow_nothing():
    order = alternate.rounds([4, 4, 4])
    seconds = [3.0] * len(order)
    # the first rounds are long (3 layers and 3 turns); the last member's last layer is the
    # only one alone, and it is slowed to the minimum like any layer built alone
    durations = alternate.step_minimums(seconds, order, 1.0, 5.0)
    assert durations[:-1] == seconds[:-1]
    assert durations[-1] == pytest.approx(5.0)


def test_alternating_pays_only_where_the_turns_cost_less_than_the_slowing_down():
    full = [[1.0] * 50, [1.0] * 50]
    slowed = [[5.0] * 50, [5.0] * 50]
    assert alternate.alternation_pays(full, slowed, 1.0, 5.0)
    assert not alternate.alternation_pays(full, slowed, 4.0, 5.0)
    assert not alternate.alternation_pays(full[:1], slowed[:1], 0.0, 5.0)
    # layers slow enough on their own gain nothing from the turns
    assert not alternate.alternation_pays([[6.0] * 50] * 2, [[6.0] * 50] * 2, 0.1, 5.0)


def test_sequential_estimate_slows_only_short_layers_and_no_slower_than_the_minimum_speed():
    assert alternate.slowed_seconds(6.0, 5.5, 20.0, 5.0) == 6.0          # long enough
    assert alternate.slowed_seconds(2.0, 1.5, 20.0, 5.0) == 5.0          # slowed to 5 s
    assert alternate.slowed_seconds(2.0, 1.5, 3.0, 5.0) == 3.0           # minimum speed
    assert alternate.sequential_seconds([[5.0, 5.0], [3.0]], 2.0) == 15.0


def test_alternated_estimate_counts_every_turn():
    # two members of two 1 s layers, turns of 2 s: 1 + 2 + 1 + 2 + 1 + 2 + 1 = 10 s; the first
    # two layers' periods are 6 s; a last layer counts what follows it to the end: member 0's
    # (1 + 2 + 1 = 4 s) is slowed by 1 s, member 1's, alone, to 5 s
    assert alternate.alternated_seconds([[1.0, 1.0], [1.0, 1.0]], 2.0, 5.0) == pytest.approx(15.0)
    for counts in itertools.product(range(1, 4), repeat=2):
        levels = [[0.5] * c for c in counts]
        assert alternate.alternated_seconds(levels, 0.0, 0.0) == pytest.approx(0.5 * sum(counts))
