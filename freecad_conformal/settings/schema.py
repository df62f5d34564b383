"""A user setting, defined once, and the checks every front end shares.

Values are held in one canonical unit per kind (mm, degrees, mm/s, mm², s, percent), which
is the unit the command line takes and FreeCAD's internal unit for the matching property.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, Iterable, Mapping, Sequence

from freecad_conformal.errors import PlanError

#: Kinds of setting and the unit a value of each kind is given in.
UNITS = {"length": "mm", "angle": "deg", "speed": "mm/s", "area": "mm^2", "volume": "mm^3",
         "time": "s", "feed": "mm/min", "percent": "%", "int": "", "float": "", "bool": "", "choice": "",
         "text": "", "direction": "", "numbers": "", "machine": "", "point": "mm", "lengths": "mm"}


class SettingError(PlanError):
    """A setting's value is out of range, of the wrong type or not one of its choices."""


@dataclass(frozen=True)
class Setting:
    """One user setting.

    key: the Python name (a field of the options built from the values).
    kind: one of UNITS.
    default: the value when the user gives none; None for "derived" (`derived` says from what).
    flag: the command-line flag (default `--key-with-dashes`); aliases are older spellings.
    prop: the FreeCAD property name (default CamelCase of the key); "" keeps it off the GUI.
    minimum/maximum: inclusive limits unless `open_minimum` (then value > minimum).
    choices: allowed values (a callable for lists known only at run time, e.g. machines).
    only_when: (key, values): the setting matters only when that setting has one of the
        values (max_cusp only for layer_mode cusp); help texts say so.
    """

    key: str
    kind: str
    default: Any
    label: str
    help: str
    group: str = "general"
    flag: str | None = None
    aliases: tuple[str, ...] = ()
    prop: str | None = None
    minimum: float | None = None
    maximum: float | None = None
    open_minimum: bool = False
    open_maximum: bool = False
    choices: Sequence[str] | Callable[[], Sequence[str]] | None = None
    derived: str = ""
    only_when: tuple[str, tuple[str, ...]] | None = None
    #: the command line must give it (the document object starts from `default`)
    required: bool = False

    def __post_init__(self) -> None:
        if self.kind not in UNITS:
            raise ValueError(f"setting {self.key}: unknown kind {self.kind!r}")

    @property
    def cli_flag(self) -> str:
        return self.flag or "--" + self.key.replace("_", "-")

    @property
    def property_name(self) -> str:
        if self.prop is not None:
            return self.prop
        return "".join(word.capitalize() for word in self.key.split("_"))

    @property
    def unit(self) -> str:
        return UNITS[self.kind]

    @property
    def condition(self) -> str:
        """ "" or where the setting applies, e.g. "layer mode adaptive or cusp"."""
        if self.only_when is None:
            return ""
        key, values = self.only_when
        return f"{key.replace('_', ' ')} {' or '.join(values)}"

    @property
    def optional(self) -> bool:
        return self.default is None

    def allowed(self) -> tuple[str, ...]:
        choices = self.choices() if callable(self.choices) else self.choices
        return tuple(choices or ())

    def describe(self) -> str:
        """How messages name the setting: its label, flag and property."""
        names = [self.cli_flag] + ([self.property_name] if self.property_name else [])
        return f"{self.label} ({' / '.join(names)})"

    def check(self, value: Any) -> Any:
        """The value in canonical form, or SettingError naming the setting and the value."""
        if value is None:
            if self.optional:
                return None
            raise SettingError(f"{self.describe()} needs a value")
        kind = self.kind
        if kind == "bool":
            if not isinstance(value, bool):
                raise SettingError(f"{self.describe()} must be true or false, got {value!r}")
            return value
        if kind in ("text", "machine"):
            return str(value)
        if kind == "choice":
            if value not in self.allowed():
                raise SettingError(f"{self.describe()} must be one of "
                                   f"{', '.join(self.allowed())}, got {value!r}")
            return value
        if kind == "direction":
            return parse_direction(value, self)
        if kind == "numbers":
            return parse_numbers(value, self)
        if kind == "point":
            return parse_point(value, self)
        if kind == "lengths":
            return tuple(self._check_number(v) for v in parse_numbers(value, self))
        return self._check_number(value)

    def _check_number(self, value: Any) -> float | int:
        try:
            number = int(value) if self.kind == "int" else float(value)
        except (TypeError, ValueError):
            raise SettingError(f"{self.describe()} must be a number, got {value!r}") from None
        if self.kind == "int" and number != float(value):
            raise SettingError(f"{self.describe()} must be a whole number, got {value!r}")
        if not math.isfinite(number):
            raise SettingError(f"{self.describe()} must be finite, got {value!r}")
        unit = f" {self.unit}" if self.unit and self.unit != "%" else self.unit
        low, high = self.minimum, self.maximum
        if low is not None and (number <= low if self.open_minimum else number < low):
            relation = ">" if self.open_minimum else ">="
            raise SettingError(f"{self.describe()} must be {relation} {low:g}{unit}, got {number:g}{unit}")
        if high is not None and (number >= high if self.open_maximum else number > high):
            relation = "<" if self.open_maximum else "<="
            raise SettingError(f"{self.describe()} must be {relation} {high:g}{unit}, got {number:g}{unit}")
        return number


#: Words a direction setting accepts besides "x,y,z".
DIRECTION_WORDS = {"as placed": (0.0, 0.0, 1.0)}


def parse_direction(value: Any, setting: Setting) -> str | tuple[float, float, float]:
    """ "auto", "as placed" (+Z) or three numbers (text "x,y,z" or a sequence), not zero."""
    if isinstance(value, str):
        text = value.strip().lower()
        if text in setting.allowed():
            return text
        if text in DIRECTION_WORDS:
            return DIRECTION_WORDS[text]
        parts = text.replace(";", ",").split(",")
    else:
        parts = list(value)
    try:
        vector = tuple(float(p) for p in parts)
    except (TypeError, ValueError):
        vector = ()
    if len(vector) != 3 or not all(map(math.isfinite, vector)) or not any(vector):
        # words are offered where the setting has choices of its own (root: auto)
        words = "".join(f"{w}, " for w in setting.allowed() + tuple(DIRECTION_WORDS)) \
            if setting.allowed() else ""
        words = f"{words[:-2]} or " if words else ""
        what = ("a zero vector" if len(vector) == 3 and not any(vector) else
                "not finite" if len(vector) == 3 else "not three numbers")
        raise SettingError(f"{setting.describe()} must be {words}a direction x,y,z (finite, "
                           f"not the zero vector), got {value!r}: {what}")
    return vector  # type: ignore[return-value]


def quantity_value(text: str, unit: str) -> float:
    """`text` in `unit` (UNITS' spelling), a number with a unit of the same kind ("0.2mm",
    "200um", "3.6 m/min"), read by FreeCAD's own Quantity parser as the task panel's fields
    read what a user types. Raises ValueError saying why not: not a quantity, or a quantity
    of another kind. FreeCAD is imported only here, for text that is no plain number (a
    command's --help stays instant)."""
    from freecad_conformal.freecad_env import import_freecad

    App, _ = import_freecad()
    try:
        quantity = App.Units.Quantity(text)
    except ValueError:
        raise ValueError("not a quantity") from None
    if quantity.Unit != App.Units.Quantity(f"1 {unit}").Unit:
        raise ValueError("a quantity of another kind")
    return float(quantity.getValueAs(unit))


def number_in(part: Any, unit: str) -> float:
    """A number, or text with a unit converted to `unit` where there is one (a flag's
    value, an element of a list setting). Raises ValueError (TypeError for a non-number
    without a unit to read it in): `quantity_value` says why text was refused."""
    try:
        return float(part)
    except (TypeError, ValueError):
        if not (unit and isinstance(part, str)):
            raise
    return quantity_value(part.strip(), unit)


def parse_numbers(value: Any, setting: Setting) -> tuple[float, ...]:
    """Numbers given as text "a, b, c" or as a sequence; all finite. Where the setting has a
    unit (lengths, a point: mm), an element may carry its own ("5mm, 0.6cm")."""
    parts = value.replace(";", ",").split(",") if isinstance(value, str) else list(value)
    try:
        numbers = tuple(number_in(p, setting.unit) for p in parts
                        if not isinstance(p, str) or p.strip())
    except (TypeError, ValueError):
        unit = f" in {setting.unit} (or each with its unit)" if setting.unit else ""
        raise SettingError(f"{setting.describe()} must be numbers a,b,c{unit}, "
                           f"got {value!r}") from None
    if not all(map(math.isfinite, numbers)):
        raise SettingError(f"{setting.describe()} must be finite numbers, got {value!r}")
    return numbers


def parse_point(value: Any, setting: Setting) -> tuple[float, float, float]:
    """Three finite coordinates (mm), given as text "x, y, z" or a sequence."""
    numbers = parse_numbers(value, setting)
    if len(numbers) != 3:
        raise SettingError(f"{setting.describe()} must be a point x,y,z, got {value!r}")
    return numbers  # type: ignore[return-value]


def defaults(settings: Iterable[Setting]) -> dict[str, Any]:
    return {s.key: s.default for s in settings}


def validate(settings: Iterable[Setting], values: Mapping[str, Any]) -> dict[str, Any]:
    """Every setting's checked value (defaults for those not given); unknown keys refused."""
    settings = list(settings)
    known = {s.key for s in settings}
    unknown = sorted(set(values) - known)
    if unknown:
        raise SettingError(f"unknown setting(s) {', '.join(unknown)}; known: {', '.join(sorted(known))}")
    return {s.key: s.check(values.get(s.key, s.default)) for s in settings}


def as_json(settings: Iterable[Setting], values: Mapping[str, Any]) -> dict[str, Any]:
    """The values for a JSON report: each with its unit, derived ones marked."""
    report = {}
    for s in settings:
        value = values.get(s.key, s.default)
        if isinstance(value, tuple):
            value = list(value)
        report[s.key] = {"value": value, "unit": s.unit} if s.unit else {"value": value}
        if value is None and s.derived:
            report[s.key]["derived"] = s.derived
    return report
