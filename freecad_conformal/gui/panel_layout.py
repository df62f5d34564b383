"""What a task panel shows, worked out without Qt: one field per editable parameter, in
words with its unit, grouped as the settings schema groups them, with the condition under
which it is shown (Setting.only_when) and the list it picks from (tools, materials, ...).

Objects made from the schema (Job, Decomposition, Feature) take labels, units, groups and
conditions from settings/; the few objects without one (Analysis, Post, Verify)
get words from their property names.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Sequence

#: Unit shown after the label for FreeCAD property types that carry one.
PROPERTY_UNITS = {"App::PropertyLength": "mm", "App::PropertyDistance": "mm",
                  "App::PropertyAngle": "°", "App::PropertySpeed": "mm/s",
                  "App::PropertyArea": "mm²", "App::PropertyVolume": "mm³",
                  "App::PropertyPercent": "%"}
#: The schema's units as a designer reads them.
UNIT_WORDS = {"deg": "°", "mm^2": "mm²", "mm^3": "mm³"}
#: Lists a field picks from, by setting key or property name.
LISTS = {"tool": "tools", "material": "materials", "dialect": "dialects", "Dialect": "dialects",
         "root": "root"}


@dataclass(frozen=True)
class FieldSpec:
    """One field of a task panel."""

    prop: str                     # the property it edits
    label: str                    # "Layer height [mm]"
    group: str                    # the group box it sits in
    type_id: str                  # FreeCAD property type
    tooltip: str = ""
    unit: str = ""
    when: tuple[str, tuple[str, ...]] | None = None   # (property, values) it is shown for
    picks: str = ""               # "tools", "materials", "dialects", "root" or ""
    empty_means: str = ""         # what an empty optional field stands for

    def shown(self, values: dict) -> bool:
        """Whether the field applies, given the current texts of the other fields."""
        if self.when is None:
            return True
        prop, allowed = self.when
        return str(values.get(prop, "")) in allowed


def words(name: str) -> str:
    """'AngularTolerance' -> 'Angular tolerance'."""
    parts = re.findall(r"[A-Z]+(?=[A-Z][a-z])|[A-Z]?[a-z]+|[A-Z]+|\d+", name)
    text = " ".join(p if p.isupper() and len(p) > 1 else p.lower() for p in parts)
    return text[:1].upper() + text[1:]


def with_unit(label: str, unit: str) -> str:
    label = label[:1].upper() + label[1:]
    return f"{label} [{unit}]" if unit else label


def _setting_unit(setting, type_id: str) -> str:
    if setting.kind == "feed":
        return "mm/s" if type_id == "App::PropertySpeed" else setting.unit
    return UNIT_WORDS.get(setting.unit, setting.unit)


def field_specs(properties: Sequence[tuple[str, str, str, str]], settings: Sequence = (),
                groups: Sequence[str] = ()) -> list[FieldSpec]:
    """Fields for `properties` ((name, type id, property group, tooltip), editable ones in
    `groups`), schema settings first matched by property name; in schema order, the other
    parameters (Kind, Mode, Machine of a Post, ...) first."""
    by_prop = {s.property_name: s for s in settings if s.property_name}
    by_key = {s.key: s for s in settings}
    others, schema = [], []
    for name, type_id, prop_group, tooltip in properties:
        if prop_group not in groups or name == "Source" or type_id.startswith("App::PropertyLink"):
            continue
        setting = by_prop.get(name)
        if setting is None:
            unit = PROPERTY_UNITS.get(type_id, "")
            others.append(FieldSpec(name, with_unit(words(name), unit), prop_group, type_id,
                                    tooltip, unit, None, LISTS.get(name, "")))
            continue
        when = None
        if setting.only_when is not None:
            key, values = setting.only_when
            target = by_key[key].property_name if key in by_key else words(key).replace(" ", "")
            when = (target, tuple(values))
        unit = _setting_unit(setting, type_id)
        schema.append(FieldSpec(name, with_unit(setting.label, unit), setting.group.capitalize(),
                                type_id, tooltip, unit, when, LISTS.get(setting.key, ""),
                                setting.derived if setting.optional else ""))
    order = {s.property_name: k for k, s in enumerate(settings)}
    schema.sort(key=lambda f: order[f.prop])
    return others + schema


def grouped(specs: Sequence[FieldSpec]) -> list[tuple[str, list[FieldSpec]]]:
    """Fields by group, groups in the order their first field comes."""
    groups: dict[str, list[FieldSpec]] = {}
    for spec in specs:
        groups.setdefault(spec.group, []).append(spec)
    return list(groups.items())
