"""Rows of three integers (rounded coordinates) found, merged and matched in numpy: meshes
match nodes by position, and Python tuples in dicts cost ~1 µs a node (a fan blade piece's
faces hold 100,000)."""
from __future__ import annotations

import numpy as np

_FIELDS = [("x", np.int64), ("y", np.int64), ("z", np.int64)]


def unique_rows(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(first, inverse) of `np.unique(keys, axis=0, return_index=True,
    return_inverse=True)` for integer rows (N, 3): the first occurrence of each distinct row,
    rows in lexicographic order, and each row's place among them. One stable lexsort on the
    columns instead of numpy's sort of the rows as records (0.10 against 0.04 s for 110,000
    rows)."""
    order = np.lexsort((keys[:, 2], keys[:, 1], keys[:, 0]))
    ordered = keys[order]
    new = np.ones(len(ordered), dtype=bool)
    new[1:] = np.any(ordered[1:] != ordered[:-1], axis=1)
    inverse = np.empty(len(keys), dtype=np.intp)
    inverse[order] = np.cumsum(new) - 1
    return order[new], inverse


def find_rows(table: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """Per row of `rows` (J, 3), its index in `table` (K, 3; distinct rows in the order
    `unique_rows` gives them), or -1 where it is not there."""
    table = np.ascontiguousarray(table, dtype=np.int64).view(_FIELDS).ravel()
    rows = np.ascontiguousarray(rows, dtype=np.int64).view(_FIELDS).ravel()
    if not len(table):
        return np.full(len(rows), -1)
    at = np.minimum(np.searchsorted(table, rows), len(table) - 1)
    return np.where(table[at] == rows, at, -1)
