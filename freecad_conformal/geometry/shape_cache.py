"""Values computed from OCC shapes, cached by shape identity.

The decomposition and the centroidal axis cut pieces again and again; a Boolean leaves most
faces and edges of a piece untouched (same TShape), so what was computed from them (face
meshes, edge angles, boxes) can be reused. Entries keep their shapes alive, so a TShape's
address cannot be recycled for another shape while cached; a hit is confirmed with `isSame`
(same TShape and location), and the orientation when the value depends on it: exact, and
far cheaper than comparing areas or boxes.
"""
from __future__ import annotations

from typing import Callable, Generic, TypeVar

from freecad_conformal.geometry.shape_access import hash_code, is_same, orientation

Value = TypeVar("Value")


#: Every cache made, for `clear_all`.
_CACHES: list["ShapeCache"] = []


def clear_all() -> None:
    """Empty every shape cache: a job starts with none (what they hold is asked again only
    within one job, and each entry keeps its shapes alive: a process planning part after
    part, as `batch` and macros do, grew ~16 MB a plan of the bottle until the limits)."""
    for cache in _CACHES:
        cache.clear()


class ShapeCache(Generic[Value]):
    """`get(shapes, compute)`: the value for this tuple of shapes, computed once. Cleared
    whole when `limit` entries are reached (a long session must not grow without bound),
    and by `clear_all` when a job starts."""

    def __init__(self, limit: int, oriented: bool) -> None:
        self.limit, self.oriented = limit, oriented
        self._buckets: dict[tuple, list[tuple[tuple, Value]]] = {}
        self._count = 0
        _CACHES.append(self)

    def _same(self, a, b) -> bool:
        return is_same(a, b) and (not self.oriented or orientation(a) == orientation(b))

    def get(self, shapes: tuple, compute: Callable[[], Value]) -> Value:
        key = tuple(hash_code(shape) for shape in shapes)
        for known, value in self._buckets.get(key, []):
            if all(self._same(a, b) for a, b in zip(known, shapes)):
                return value
        if self._count >= self.limit:
            self._buckets.clear()
            self._count = 0
        value = compute()
        self._buckets.setdefault(key, []).append((shapes, value))
        self._count += 1
        return value

    def get_keyed(self, shapes: tuple, key, compute: Callable[[], object]):
        """The value for these shapes and a hashable `key` (a direction, a machine's
        travel), computed once: `get` of a dict of values by key."""
        made = self.get(shapes, dict)
        if key not in made:
            made[key] = compute()
        return made[key]

    def peek(self, shapes: tuple) -> Value | None:
        """The value cached for these shapes, None when there is none (nothing computed)."""
        key = tuple(hash_code(shape) for shape in shapes)
        for known, value in self._buckets.get(key, []):
            if all(self._same(a, b) for a, b in zip(known, shapes)):
                return value
        return None

    def discard(self, shapes: tuple) -> bool:
        """Forget the value cached for these shapes; whether there was one."""
        key = tuple(hash_code(shape) for shape in shapes)
        bucket = self._buckets.get(key, [])
        for index, (known, _) in enumerate(bucket):
            if all(self._same(a, b) for a, b in zip(known, shapes)):
                del bucket[index]
                self._count -= 1
                return True
        return False

    def clear(self) -> None:
        self._buckets.clear()
        self._count = 0
