"""Integer rows merged and matched in numpy, against numpy's own unique rows and a dict."""
from __future__ import annotations

import numpy as np
import pytest

from freecad_conformal.geometry.rows import find_rows, unique_rows


def _rows(seed: int, distinct: int, count: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    # Signed values with many repeats and ties in the first columns: the order is
    # lexicographic on signed integers, repeats keep their first occurrence.
    table = rng.integers(-3, 3, size=(distinct, 3)) * 10**8 + rng.integers(-2, 2, size=(distinct, 3))
    return table[rng.integers(0, distinct, size=count)]


@pytest.mark.parametrize("seed, distinct, count", [(0, 50, 400), (1, 5000, 20000), (2, 1, 7)])
def test_unique_rows_are_numpys_unique_rows(seed, distinct, count):
    keys = _rows(seed, distinct, count)
    _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    mine_first, mine_inverse = unique_rows(keys)
    assert np.array_equal(mine_first, first)
    assert np.array_equal(mine_inverse, inverse.reshape(-1))


def test_no_rows_have_no_unique_rows():
    first, inverse = unique_rows(np.zeros((0, 3), dtype=np.int64))
    assert len(first) == 0 and len(inverse) == 0


def test_found_rows_are_those_a_dict_finds():
    keys = _rows(3, 300, 2000)
    first, _ = unique_rows(keys)
    table = keys[first]
    where = {tuple(row): k for k, row in enumerate(table.tolist())}
    probes = np.vstack([keys[::7], keys[::11] + 1, [[10**9, 0, 0]]])
    expected = [where.get(tuple(row), -1) for row in probes.tolist()]
    found = find_rows(table, probes)
    assert found.tolist() == expected
    assert (found == -1).any() and (found >= 0).any()
    assert find_rows(np.zeros((0, 3), dtype=np.int64), probes).tolist() == [-1] * len(probes)
