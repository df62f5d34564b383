"""Connected components from edge arrays, against a plain breadth-first search."""
from __future__ import annotations

import numpy as np
import pytest

from freecad_conformal.geometry.components import connected_labels


def _components_by_search(count, a, b):
    neighbours = [[] for _ in range(count)]
    for i, j in zip(a, b):
        neighbours[i].append(j)
        neighbours[j].append(i)
    label = [-1] * count
    next_label = 0
    for start in range(count):
        if label[start] >= 0:
            continue
        label[start] = next_label
        queue = [start]
        while queue:
            node = queue.pop()
            for other in neighbours[node]:
                if label[other] < 0:
                    label[other] = next_label
                    queue.append(other)
        next_label += 1
    return label


def _same_partition(x, y) -> bool:
    pairs = set(zip(x, y))
    return len(pairs) == len(set(x)) == len(set(y))


@pytest.mark.parametrize("seed", range(8))
def test_labels_match_a_search_on_random_sparse_graphs(seed):
    rng = np.random.default_rng(seed)
    count = int(rng.integers(1, 400))
    edges = int(rng.integers(0, count))
    a, b = rng.integers(0, count, edges), rng.integers(0, count, edges)
    labels = connected_labels(count, a, b)
    assert sorted(set(labels.tolist())) == list(range(labels.max() + 1))
    assert _same_partition(labels.tolist(), _components_by_search(count, a, b))


def test_a_long_path_given_backwards_is_one_component():
    count = 5000
    a = np.arange(count - 1)[::-1]
    labels = connected_labels(count, a, a + 1)
    assert set(labels.tolist()) == {0}


def test_isolated_nodes_keep_their_own_labels():
    labels = connected_labels(4, np.array([0]), np.array([2]))
    assert labels[0] == labels[2] and len({labels[0], labels[1], labels[3]}) == 3
