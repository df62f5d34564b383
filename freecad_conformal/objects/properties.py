"""Adding properties to FeaturePython objects (idempotent, so restored files keep working
when a newer version adds a property)."""
from __future__ import annotations

import functools
from typing import Any, Callable, Sequence

#: (type, name, group, tooltip, default) as FreeCAD's addProperty takes them, plus a value.
PropertySpec = tuple[str, str, str, str, Any]


def add_properties(obj, specs: Sequence[PropertySpec], read_only: Sequence[str] = ()) -> None:
    """Add each missing property and set its default; mark outputs read-only."""
    for type_name, name, group, tip, default in specs:
        if name in obj.PropertiesList:
            continue
        obj.addProperty(type_name, name, group, tip)
        if isinstance(default, tuple) and type_name == "App::PropertyEnumeration":
            setattr(obj, name, list(default))
            setattr(obj, name, default[0])
        elif default is not None:
            setattr(obj, name, default)
    for name in read_only:
        obj.setEditorMode(name, 1)


def source_shape(obj, what: str):
    """The shape of the object linked by `obj.Source`; clear error when unset or empty."""
    from freecad_conformal.errors import GeometryError

    source = obj.Source
    if source is None:
        raise GeometryError(f"{obj.Label}: no source body is linked ({what} needs one)")
    shape = getattr(source, "Shape", None)
    if shape is None or shape.isNull():
        raise GeometryError(f"{obj.Label}: source {source.Label} has no shape")
    return shape


def vector3(value) -> tuple[float, float, float]:
    """A FreeCAD Vector as a plain tuple."""
    return (float(value.x), float(value.y), float(value.z))


class StoredState:
    """No Python state: everything lives in properties (FreeCAD 0.20 and 1.x names)."""

    def dumps(self):
        return None

    def loads(self, _state) -> None:
        return None

    def __getstate__(self):
        return None

    def __setstate__(self, _state) -> None:
        return None


def reports_errors(execute: Callable) -> Callable:
    """Wrap a proxy's execute: a ConformalError is printed as one line naming the object in
    the report view, then re-raised so FreeCAD marks the object as failed (no dialog)."""
    @functools.wraps(execute)
    def wrapper(self, obj):
        from freecad_conformal.errors import ConformalError

        try:
            return execute(self, obj)
        except ConformalError as exc:
            import FreeCAD

            FreeCAD.Console.PrintError(f"Conformal: {obj.Label} failed: {exc}\n")
            raise
    return wrapper
