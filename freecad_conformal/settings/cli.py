"""Command-line flags generated from settings, and the values read back from argparse."""
from __future__ import annotations

import argparse
from typing import Any, Iterable

from freecad_conformal.settings.schema import UNITS, Setting, number_in

#: Kinds whose flags take a quantity: a plain number is in the kind's unit (UNITS), and a
#: number with a unit is converted to it ("0.2mm", "200um", "3.6 m/min", "0.5 rad"), read
#: by FreeCAD's own parser as the task panel's fields read what a user types.
QUANTITY_KINDS = ("length", "angle", "speed", "area", "volume", "time", "feed")

#: An example of a quantity with another unit, per kind, for the message that refuses one.
_EXAMPLES = {"length": "0.2mm or 200um", "angle": "45deg or 0.5rad", "speed": "60mm/s or 3.6m/min",
             "area": "70mm^2 or 0.7cm^2", "volume": "500mm^3 or 0.5cm^3", "time": "5s or 1min",
             "feed": "1800mm/min or 30mm/s"}


def quantity_type(kind: str):
    """The argparse type of a flag of `kind` (QUANTITY_KINDS): its value in the kind's unit."""
    unit = UNITS[kind]

    def parse(text: str) -> float:
        try:
            return number_in(text, unit)
        except ValueError as reason:
            raise argparse.ArgumentTypeError(
                f"{text!r} is {reason}: give a {kind} in {unit} (a plain number) or with its "
                f"unit, e.g. {_EXAMPLES[kind]}") from None

    parse.__name__ = kind        # argparse names the type in its own messages
    return parse


def _percent(text: str) -> float:
    """A percentage, with or without its % sign."""
    try:
        return float(text.strip().removesuffix("%"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a percentage: give a number, e.g. 20 "
                                         "or 20%") from None


_TYPES = {"int": int, "percent": _percent, "float": float,
          **{kind: quantity_type(kind) for kind in QUANTITY_KINDS}}


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
