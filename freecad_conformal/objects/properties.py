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
    """Wrap a proxy's execute: a failure is printed as one line naming the object in the
    report view, its traceback goes to the log only, and an exception carrying just the
    message is raised so FreeCAD marks the object as failed (no dialog). FreeCAD quotes
    where that exception was raised (this wrapper): two short lines, not the whole stack."""
    @functools.wraps(execute)
    def wrapper(self, obj):
        try:
            return execute(self, obj)
        except Exception as exc:   # noqa: BLE001 - every failure is reported the same way
            import traceback

            import FreeCAD

            message = one_line(exc)
            FreeCAD.Console.PrintLog(traceback.format_exc())
            FreeCAD.Console.PrintError(f"Conformal: {obj.Label} failed: {message}\n")
            short = type(exc)(message) if _rebuildable(exc) else RuntimeError(message)
        raise short.with_traceback(None) from None
    return wrapper


def one_line(exc: BaseException) -> str:
    """The first line of an error's message (its type when it has none)."""
    from freecad_conformal.errors import ConformalError

    text = str(exc).strip()
    first = text.splitlines()[0] if text else type(exc).__name__
    return first if isinstance(exc, ConformalError) else f"{type(exc).__name__}: {first}"


def _rebuildable(exc: BaseException) -> bool:
    """Whether the error's class takes one message (ours do; OCC's may not)."""
    from freecad_conformal.errors import ConformalError

    return isinstance(exc, ConformalError)


#: FreeCAD property type of each setting kind (settings/schema.py); quantities are held in
#: FreeCAD's internal units, which are the schema's canonical ones (mm, deg, mm/s, mm², mm³).
PROPERTY_TYPES = {"length": "App::PropertyLength", "angle": "App::PropertyAngle",
                  "speed": "App::PropertySpeed", "area": "App::PropertyArea",
                  "volume": "App::PropertyVolume", "time": "App::PropertyFloat",
                  "feed": "App::PropertySpeed", "numbers": "App::PropertyString",
                  "percent": "App::PropertyPercent", "int": "App::PropertyInteger",
                  "float": "App::PropertyFloat", "bool": "App::PropertyBool",
                  "choice": "App::PropertyEnumeration", "machine": "App::PropertyEnumeration",
                  "text": "App::PropertyString", "direction": "App::PropertyString",
                  "point": "App::PropertyString", "lengths": "App::PropertyString"}
#: Feeds are set in mm/min (as G-code F words); FreeCAD's speed properties hold mm/s.
SECONDS_PER_MINUTE = 60.0
#: Optional settings whose zero is a real value are text properties: empty means derived.
ZERO_IS_A_VALUE = ("angle",)


def _property_type(setting) -> str:
    if setting.optional and setting.kind in ZERO_IS_A_VALUE:
        return "App::PropertyString"
    return PROPERTY_TYPES[setting.kind]


def _tooltip(setting) -> str:
    unit = f" ({setting.unit})" if setting.kind in ("time", "float") and setting.unit else ""
    derived = f"; empty or 0: {setting.derived}" if setting.optional and setting.derived else ""
    only = f"; only with {setting.condition}" if setting.condition else ""
    return f"{setting.help[0].upper()}{setting.help[1:]}{unit}{derived}{only} [{setting.cli_flag}]"


def setting_properties(settings, group: str) -> list[PropertySpec]:
    """Property specs for settings that have a property (settings/schema.Setting)."""
    specs: list[PropertySpec] = []
    for setting in settings:
        if not setting.property_name:
            continue
        type_name = _property_type(setting)
        if type_name == "App::PropertyEnumeration":
            default: Any = tuple(sorted(setting.allowed(), key=lambda c: c != setting.default))
        elif setting.default is None:
            default = "" if type_name == "App::PropertyString" else 0
        elif isinstance(setting.default, tuple):
            default = ", ".join(f"{c:g}" for c in setting.default)
        elif setting.kind == "feed":
            default = setting.default / SECONDS_PER_MINUTE
        elif type_name == "App::PropertyPercent":
            default = int(round(setting.default))
        else:
            default = setting.default
        specs.append((type_name, setting.property_name, group, _tooltip(setting), default))
    return specs


def values_from_object(obj, settings) -> dict[str, Any]:
    """Setting values from the object's properties (not yet checked). A property missing from
    an older saved file takes the setting's default; an empty or zero optional is derived."""
    values: dict[str, Any] = {}
    for setting in settings:
        name = setting.property_name
        if not name or name not in obj.PropertiesList:
            values[setting.key] = setting.default
            continue
        value = getattr(obj, name)
        value = getattr(value, "Value", value)     # a Quantity's value in internal units
        if setting.kind == "feed":
            value = value * SECONDS_PER_MINUTE
        if isinstance(value, str):
            value = value.strip()
        if setting.optional and value in ("", 0, 0.0):
            value = None
        values[setting.key] = value
    return values


def set_values(obj, settings, values: dict[str, Any]) -> None:
    """Set the properties of `settings` keys in `values` (how a script or an example sets
    up an object): the inverse of values_from_object. Unknown keys raise KeyError."""
    by_key = {s.key: s for s in settings}
    for key, value in values.items():
        if key not in by_key or not by_key[key].property_name:
            raise KeyError(f"{obj.Label}: no property for setting {key!r}")
        setting = by_key[key]
        if value is None:
            value = "" if _property_type(setting) == "App::PropertyString" else 0
        elif isinstance(value, (tuple, list)):
            value = ", ".join(f"{float(c):.12g}" for c in value)
        elif setting.kind == "feed":
            value = value / SECONDS_PER_MINUTE
        setattr(obj, setting.property_name, value)
