"""Command-line flags generated from settings, and the values read back from argparse."""
from __future__ import annotations

import argparse
from typing import Any, Iterable

from freecad_conformal.settings.schema import Setting

_TYPES = {"int": int, "length": float, "angle": float, "speed": float, "area": float,
          "volume": float, "time": float, "feed": float, "percent": float, "float": float}


def _help(setting: Setting) -> str:
    unit = f"{setting.unit}; " if setting.unit and setting.unit != "%" else ""
    if setting.optional:
        default = f"default: {setting.derived}" if setting.derived else "optional"
    elif setting.kind == "bool":
        default = f"default {'on' if setting.default else 'off'}"
    elif isinstance(setting.default, tuple):
        default = "default " + ",".join(f"{c:g}" for c in setting.default)
    else:
        default = f"default {setting.default:g}" if isinstance(setting.default, float) \
            else f"default {setting.default}"
    only = f"; only with {setting.condition}" if setting.condition else ""
    return f"{setting.help} ({unit}{default}{only})"


def add_arguments(parser: argparse.ArgumentParser, settings: Iterable[Setting],
                  groups: dict[str, Any] | None = None) -> None:
    """One flag per setting, in argument groups named by the settings' groups (`groups`:
    ones the command made already, by name). Flags leave unset values as None;
    `values_from_args` fills in the schema's defaults, so argparse never holds a second
    copy of a default."""
    groups = dict(groups or {})
    for setting in settings:
        group = groups.get(setting.group)
        if group is None:
            group = groups[setting.group] = parser.add_argument_group(setting.group)
        flags = (setting.cli_flag, *setting.aliases)
        common: dict[str, Any] = dict(dest=setting.key, default=None, help=_help(setting))
        if setting.required:
            common["required"] = True
            common["help"] = setting.help + (f" ({setting.unit})" if setting.unit else "")
        if setting.kind == "bool":
            group.add_argument(*flags, action=argparse.BooleanOptionalAction, **common)
        elif setting.kind == "choice":
            group.add_argument(*flags, choices=setting.allowed(), **common)
        elif setting.kind in _TYPES:
            group.add_argument(*flags, type=_TYPES[setting.kind], metavar=setting.unit.upper()
                               .replace("^", "") or setting.kind.upper(), **common)
        else:
            group.add_argument(*flags, **common)


def values_from_args(args: argparse.Namespace, settings: Iterable[Setting]) -> dict[str, Any]:
    """The given values; settings left unset take the schema default (not yet checked)."""
    values = {}
    for setting in settings:
        value = getattr(args, setting.key, None)
        values[setting.key] = setting.default if value is None else value
    return values
