"""The build order keeps concurrent sub-parts consecutive: the collision check lets them
pass each other only because the toolpath builds consecutive ones together."""
from __future__ import annotations

import numpy as np
import pytest

from freecad_conformal.decomposition.build_order import build_order
from freecad_conformal.decomposition.subparts import SubPart

UP = np.array([0.0, 0.0, 1.0])


class Checker:
    """No collisions; `pairs` are the concurrent sub-parts."""

    def __init__(self, pairs: set[frozenset[int]], blocked: dict[int, set[int]] | None = None):
        self.pairs = pairs
        self.blocked = blocked or {}

    def concurrent_with(self, index: int, other: int) -> bool:
        return frozenset((index, other)) in self.pairs

    def hits(self, index: int, built: list[int]) -> list[int]:
        return [i for i in built if i in self.blocked.get(index, set())]


def _plate_and_brothers() -> list[SubPart]:
    """A plate (0) with three brothers on it: 1 and 3 concurrent (both +Z from the plate's
    top), 2 built along +X, with a volume between theirs."""
    return [SubPart(0, None, UP, volume=100.0),
            SubPart(1, None, UP, volume=30.0, parent=0),
            SubPart(2, None, np.array([1.0, 0.0, 0.0]), volume=20.0, parent=0),
            SubPart(3, None, UP, volume=10.0, parent=0)]


def test_concurrent_brothers_are_built_one_after_the_other():
    subparts = _plate_and_brothers()
    assert build_order(subparts) == [0, 1, 2, 3]          # largest first, no check
    order = build_order(subparts, checker=Checker({frozenset((1, 3))}))
    assert order == [0, 1, 3, 2]


def test_a_mate_that_collides_next_gives_way_to_another_order():
    """When the mate cannot come next, the search backtracks rather than split the pair."""
    subparts = _plate_and_brothers()
    # 2 would hit 1 once 1 is built: 1 first (largest) then its mate 3 leaves 2 blocked.
    checker = Checker({frozenset((1, 3))}, blocked={2: {1}})
    assert build_order(subparts, checker=checker) == [0, 2, 1, 3]


def test_no_order_at_all_still_names_the_blocked_sub_parts():
    subparts = _plate_and_brothers()
    with pytest.raises(Exception, match="no collision-free build order"):
        build_order(subparts, checker=Checker(set(), blocked={1: {2}, 2: {1}}))
