"""Reading values out of JSON objects with messages that name the object, the key and the value.

A tiny hand-written schema check (the Addon Manager offers no `jsonschema`): each reader takes
the object, the key and a `where` text such as "tool 'uv_large' (uv_large.json)", and raises
`ProcessError` naming all three when the value is missing, of the wrong type or out of range.
"""
from __future__ import annotations

import math
from typing import Any, Iterable, Mapping

from freecad_conformal.errors import ProcessError

_MISSING = object()


def check_keys(data: Mapping[str, Any], allowed: Iterable[str], where: str) -> None:
    """Reject unknown keys: a misspelt key would otherwise be silently ignored."""
    if not isinstance(data, Mapping):
        raise ProcessError(f"{where}: expected a JSON object, got {type(data).__name__}")
    unknown = sorted(set(data) - set(allowed))
    if unknown:
        raise ProcessError(f"{where}: unknown key(s) {', '.join(map(repr, unknown))}; "
                           f"allowed: {', '.join(sorted(allowed))}")


def number(data: Mapping[str, Any], key: str, where: str, *, default: Any = _MISSING,
           minimum: float | None = None, maximum: float | None = None,
           exclusive_minimum: bool = False) -> Any:
    """A finite number within [minimum, maximum] (minimum excluded if `exclusive_minimum`)."""
    value = data.get(key, _MISSING)
    if value is _MISSING or value is None:
        if default is _MISSING:
            raise ProcessError(f"{where}: missing required number {key!r}")
        return default
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ProcessError(f"{where}: {key!r} must be a finite number, got {value!r}")
    if minimum is not None and (value <= minimum if exclusive_minimum else value < minimum):
        relation = ">" if exclusive_minimum else ">="
        raise ProcessError(f"{where}: {key!r} must be {relation} {minimum:g}, got {value!r}")
    if maximum is not None and value > maximum:
        raise ProcessError(f"{where}: {key!r} must be <= {maximum:g}, got {value!r}")
    return float(value)


def integer(data: Mapping[str, Any], key: str, where: str, *, default: Any = _MISSING,
            minimum: int | None = None) -> Any:
    value = data.get(key, _MISSING)
    if value is _MISSING or value is None:
        if default is _MISSING:
            raise ProcessError(f"{where}: missing required integer {key!r}")
        return default
    if isinstance(value, bool) or not isinstance(value, int):
        raise ProcessError(f"{where}: {key!r} must be an integer, got {value!r}")
    if minimum is not None and value < minimum:
        raise ProcessError(f"{where}: {key!r} must be >= {minimum}, got {value!r}")
    return value


def text(data: Mapping[str, Any], key: str, where: str, *, default: Any = _MISSING,
         choices: Iterable[str] | None = None, non_empty: bool = True) -> Any:
    value = data.get(key, _MISSING)
    if value is _MISSING or value is None:
        if default is _MISSING:
            raise ProcessError(f"{where}: missing required text {key!r}")
        return default
    if not isinstance(value, str) or (non_empty and not value.strip()):
        raise ProcessError(f"{where}: {key!r} must be a non-empty string, got {value!r}")
    if choices is not None and value not in set(choices):
        raise ProcessError(f"{where}: {key!r} must be one of {', '.join(sorted(choices))}; "
                           f"got {value!r}")
    return value


def number_list(data: Mapping[str, Any], key: str, where: str, *,
                minimum: float | None = None, exclusive_minimum: bool = False) -> list[float]:
    """A (possibly empty) list of numbers, each checked like `number`."""
    values = data.get(key, [])
    if not isinstance(values, list):
        raise ProcessError(f"{where}: {key!r} must be a list of numbers, got {values!r}")
    return [number({key: v}, key, f"{where} [{i}]", minimum=minimum,
                   exclusive_minimum=exclusive_minimum) for i, v in enumerate(values)]


def mapping(data: Mapping[str, Any], key: str, where: str) -> dict[str, Any]:
    value = data.get(key, {})
    if not isinstance(value, Mapping):
        raise ProcessError(f"{where}: {key!r} must be a JSON object, got {value!r}")
    return dict(value)
