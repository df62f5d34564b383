"""Shape methods and properties read through their type, for the hot paths.

FreeCAD 1.x first tries every attribute looked up on a shape object as a sub-element name
(is `isSame` an element like "Face3"?): 3-4 us a lookup, against 0.4 us in 0.20, paid again
at each `face.isSame`, `shape.hashCode`, `vertex.Point`. The same method or property taken
from the type skips that and costs 0.1-0.3 us in both: the shape caches make thousands of
such lookups a plan (the jack's plan choice: 9,700).
"""
from __future__ import annotations

from typing import Callable

from freecad_conformal.freecad_env import import_freecad

_BOUND: dict[str, Callable] = {}


def _bind() -> dict[str, Callable]:
    if not _BOUND:
        _, Part = import_freecad()
        _BOUND.update(
            is_same=Part.Shape.isSame, hash_code=Part.Shape.hashCode,
            orientation=_getter(Part.Shape, "Orientation"),
            point=_getter(Part.Vertex, "Point"))
    return _BOUND


def _getter(kind: type, name: str) -> Callable:
    """The C getter of property `name` of `kind` (read on the type, a property is its
    descriptor)."""
    descriptor = getattr(kind, name)
    return lambda shape: descriptor.__get__(shape, kind)


def is_same(a, b) -> bool:
    """`a.isSame(b)`: the same TShape and location."""
    return (_BOUND or _bind())["is_same"](a, b)


def hash_code(shape) -> int:
    """`shape.hashCode()`."""
    return (_BOUND or _bind())["hash_code"](shape)


def orientation(shape) -> str:
    """`shape.Orientation`."""
    return (_BOUND or _bind())["orientation"](shape)


def point(vertex) -> tuple[float, float, float]:
    """`tuple(vertex.Point)`."""
    return tuple((_BOUND or _bind())["point"](vertex))


def placement_move(original, moved):
    """The FreeCAD Matrix of the rigid move from `original`'s placement to `moved`'s: what a
    copy turned or translated from it was given."""
    return moved.Placement.multiply(original.Placement.inverse()).toMatrix()
