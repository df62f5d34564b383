"""Two-level designs: 2^k full and 2^(k−p) fractional factorials, centre points, replicates,
a seeded random run order, the alias structure and the resolution. numpy only.

Runs are generated in standard (Yates) order: the first base factor alternates fastest.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

from freecad_conformal.errors import ProcessError
from freecad_conformal.process import json_fields as schema
from freecad_conformal.process.doe.words import (
    FACTOR_LETTERS, AliasClass, Generator, alias_classes, defining_group, parse_generators,
    resolution, roman)

#: A real value this close (relative to the half range) to a level is that level; CSV
#: round-trips print 12 significant digits, so 1e-6 is loose enough and still exact.
LEVEL_MATCH_RELATIVE = 1e-6
#: Largest design generated: 2^16 runs per replicate is far beyond any physical study.
MAX_BASE_FACTORS = 16


@dataclass
class Factor:
    """A factor with its real levels: numbers (coded by the centre and half range, so
    centre points are possible) or two texts (a qualitative factor, ±1 only)."""

    name: str
    label: str = ""
    low: float | str = -1.0
    high: float | str = 1.0
    unit: str = ""

    def __post_init__(self) -> None:
        if self.name not in FACTOR_LETTERS or len(self.name) != 1:
            raise ProcessError(f"factor name {self.name!r} must be one capital letter other "
                               "than I (I is the identity word)")
        if self.is_numeric:
            if not all(math.isfinite(v) for v in self._numbers()) or self.low == self.high:
                raise ProcessError(f"factor {self.name}: levels must be two different finite "
                                   f"numbers, got {self.low!r} and {self.high!r}")
        elif not (isinstance(self.low, str) and isinstance(self.high, str)) or self.low == self.high:
            raise ProcessError(f"factor {self.name}: levels must be two numbers or two different "
                               f"texts, got {self.low!r} and {self.high!r}")

    @property
    def is_numeric(self) -> bool:
        return all(isinstance(v, (int, float)) and not isinstance(v, bool)
                   for v in (self.low, self.high))

    def _numbers(self) -> tuple[float, float]:
        """(low, high) of a numeric factor as floats (callers check `is_numeric`)."""
        return float(self.low), float(self.high)

    def real(self, coded: float) -> float | str:
        """The real level for a coded value (numeric factors also between −1 and +1)."""
        if self.is_numeric:
            low, high = self._numbers()
            return (low + high) / 2 + coded * (high - low) / 2
        if coded in (-1, 1):
            return self.high if coded > 0 else self.low
        raise ProcessError(f"factor {self.name} ({self.low} / {self.high}) is qualitative: only "
                           f"coded -1 or +1, not {coded:g}")

    def code(self, value: Any) -> float:
        """The coded value of a real level read from a sheet (number or text)."""
        if self.is_numeric:
            try:
                number = float(value)
            except (TypeError, ValueError):
                raise ProcessError(f"factor {self.name}: {value!r} is not a number") from None
            low, high = self._numbers()
            half = (high - low) / 2
            coded = (number - (low + high) / 2) / half
            for level in (-1.0, 0.0, 1.0):
                if abs(coded - level) <= LEVEL_MATCH_RELATIVE:
                    return level
            raise ProcessError(f"factor {self.name}: {value!r} is none of the levels "
                               f"{low:g}, {(low + high) / 2:g}, {high:g}")
        text = str(value).strip()
        for written, coded in ((self.low, -1.0), (self.high, 1.0), ("-1", -1.0), ("1", 1.0),
                               ("+1", 1.0)):
            if text == str(written):
                return coded
        raise ProcessError(f"factor {self.name}: {value!r} is neither {self.low!r} nor {self.high!r}")

    def to_dict(self) -> dict:
        return {"name": self.name, "label": self.label, "low": self.low, "high": self.high,
                "unit": self.unit}

    @classmethod
    def from_dict(cls, data: dict, where: str) -> "Factor":
        schema.check_keys(data, ("name", "label", "low", "high", "unit"), where)
        low, high = data.get("low", -1.0), data.get("high", 1.0)
        return cls(schema.text(data, "name", where), schema.text(data, "label", where, default="",
                                                                 non_empty=False),
                   low, high, schema.text(data, "unit", where, default="", non_empty=False))


def default_factors(count: int) -> list[Factor]:
    if not 2 <= count <= len(FACTOR_LETTERS):
        raise ProcessError(f"a design needs 2 to {len(FACTOR_LETTERS)} factors, got {count}")
    return [Factor(letter) for letter in FACTOR_LETTERS[:count]]


@dataclass
class Run:
    """One row of the run sheet."""

    run_order: int      # 1-based, the order to run it in
    std_order: int      # 1-based standard order of the design point (centre points last)
    replicate: int      # 1-based
    coded: tuple[float, ...]

    @property
    def is_centre(self) -> bool:
        return all(x == 0 for x in self.coded)


@dataclass
class Design:
    """A two-level (fractional) factorial design with its runs in run order."""

    factors: list[Factor]
    generators: list[Generator] = field(default_factory=list)
    replicates: int = 1
    centre_points: int = 0
    seed: int | None = None
    randomize: bool = True
    response: str = "y"

    def __post_init__(self) -> None:
        names = [f.name for f in self.factors]
        if len(set(names)) != len(names):
            raise ProcessError(f"duplicate factor names in {''.join(names)}")
        if len(self.factors) < 2:
            raise ProcessError(f"a design needs at least 2 factors, got {len(self.factors)}")
        if self.replicates < 1:
            raise ProcessError(f"replicates must be >= 1, got {self.replicates}")
        if self.centre_points < 0:
            raise ProcessError(f"centre points must be >= 0, got {self.centre_points}")
        if self.centre_points and not all(f.is_numeric for f in self.factors):
            text = ", ".join(f.name for f in self.factors if not f.is_numeric)
            raise ProcessError(f"centre points need numeric factors; {text} are qualitative")
        if len(self.base_factors) > MAX_BASE_FACTORS:
            raise ProcessError(f"{len(self.base_factors)} base factors give "
                               f"2^{len(self.base_factors)} runs; at most {MAX_BASE_FACTORS}")

    @classmethod
    def build(cls, factors: Sequence[Factor] | int, generators: Sequence[str] = (),
              **options: Any) -> "Design":
        """A design from factors (or a factor count) and generator texts ('D=ABC', 'I=ABCD')."""
        factor_list = default_factors(factors) if isinstance(factors, int) else list(factors)
        parsed = parse_generators(generators, [f.name for f in factor_list])
        return cls(factor_list, parsed, **options)

    @property
    def names(self) -> list[str]:
        return [f.name for f in self.factors]

    @property
    def base_factors(self) -> list[str]:
        generated = {g.factor for g in self.generators}
        return [name for name in self.names if name not in generated]

    def factor(self, name: str) -> Factor:
        for f in self.factors:
            if f.name == name:
                return f
        raise ProcessError(f"no factor {name!r} in the design ({''.join(self.names)})")

    @property
    def defining_relation(self) -> list[tuple[str, int]]:
        return defining_group(g.defining_word() for g in self.generators)

    @property
    def resolution(self) -> int | None:
        return resolution(self.defining_relation)

    def alias_structure(self) -> list[AliasClass]:
        return alias_classes(self.base_factors, self.defining_relation)

    def title(self) -> str:
        k, p = len(self.factors), len(self.generators)
        kind = f"2^({k}-{p}) fractional factorial" if p else f"2^{k} full factorial"
        res = f", resolution {roman(self.resolution)}" if p else ""
        return f"{kind}{res}: {self.point_count} design points x {self.replicates} replicates" + (
            f" + {self.centre_points} centre points" if self.centre_points else "")

    @property
    def point_count(self) -> int:
        return 2 ** len(self.base_factors)

    def matrix(self) -> np.ndarray:
        """Coded design points (±1) in standard order, one column per factor in order."""
        base = self.base_factors
        index = np.arange(self.point_count)
        columns = {name: np.where((index >> bit) & 1, 1.0, -1.0) for bit, name in enumerate(base)}
        for g in self.generators:
            column = np.full(self.point_count, float(g.sign))
            for letter in g.word:
                column = column * columns[letter]
            columns[g.factor] = column
        return np.column_stack([columns[name] for name in self.names])

    def runs(self) -> list[Run]:
        """Every run: points × replicates, then centre points, in (seeded) random order."""
        points = self.matrix()
        rows = [(i + 1, rep + 1, tuple(points[i])) for rep in range(self.replicates)
                for i in range(self.point_count)]
        rows += [(self.point_count + c + 1, 1, tuple(0.0 for _ in self.factors))
                 for c in range(self.centre_points)]
        order = (np.random.default_rng(self.seed).permutation(len(rows)) if self.randomize
                 else np.arange(len(rows)))
        return [Run(position + 1, *rows[index]) for position, index in enumerate(order)]

    def to_dict(self) -> dict:
        return {"format": "conformal-doe", "version": 1,
                "factors": [f.to_dict() for f in self.factors],
                "generators": [str(g) for g in self.generators],
                "replicates": self.replicates, "centre_points": self.centre_points,
                "seed": self.seed, "randomize": self.randomize, "response": self.response}

    @classmethod
    def from_dict(cls, data: dict, where: str = "design") -> "Design":
        schema.check_keys(data, ("format", "version", "factors", "generators", "replicates",
                                 "centre_points", "seed", "randomize", "response"), where)
        if data.get("format") != "conformal-doe":
            raise ProcessError(f"{where}: 'format' must be 'conformal-doe', got {data.get('format')!r}")
        raw_factors = data.get("factors")
        if not isinstance(raw_factors, list):
            raise ProcessError(f"{where}: 'factors' must be a list")
        factors = [Factor.from_dict(f, f"{where} factor {i + 1}") for i, f in enumerate(raw_factors)]
        generators = data.get("generators", [])
        if not isinstance(generators, list) or not all(isinstance(g, str) for g in generators):
            raise ProcessError(f"{where}: 'generators' must be a list of texts like 'D=ABC'")
        seed = data.get("seed")
        return cls.build(factors, generators,
                         replicates=schema.integer(data, "replicates", where, default=1, minimum=1),
                         centre_points=schema.integer(data, "centre_points", where, default=0,
                                                      minimum=0),
                         seed=None if seed is None else schema.integer(data, "seed", where),
                         randomize=bool(data.get("randomize", True)),
                         response=schema.text(data, "response", where, default="y"))
