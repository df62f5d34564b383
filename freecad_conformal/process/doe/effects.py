"""Per-run data (from replicates or from published summaries) and the effects of a two-level
design on the mean and on ln s².

effect = mean of the response where the contrast is +1 minus the mean where it is −1, taken
over the design points (each point weighs the same). Contrasts are found from the points
themselves: every product of factor columns, grouped into alias classes by equal columns (up
to sign); constant products form the defining relation. So a sheet analyses without a design
file, and with one the labels are the same (`doe_words.label_key`).
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from freecad_conformal.errors import ProcessError
from freecad_conformal.process.doe.sheet import Table, group_runs
from freecad_conformal.process.doe.words import label_key

#: Largest factor count for which every interaction word is enumerated (2^k − 1 words).
MAX_ANALYSED_FACTORS = 14


@dataclass
class RunData:
    """One row per design point (corner): coded levels, mean, ln s² (None if unknown) and
    replicate count; centre points are kept apart (they carry no contrast)."""

    names: list[str]
    points: np.ndarray
    means: np.ndarray
    ln_s2: np.ndarray | None
    counts: np.ndarray
    source: str
    centre_values: np.ndarray = field(default_factory=lambda: np.empty(0))
    notes: list[str] = field(default_factory=list)

    @classmethod
    def from_replicates(cls, table: Table, response: str) -> "RunData":
        values = table.columns[response]
        groups = group_runs(table.coded)
        centre = [g for g in groups if not table.coded[g[0]].any()]
        corners = [g for g in groups if table.coded[g[0]].any()]
        counts = np.array([len(g) for g in corners])
        means = np.array([values[g].mean() for g in corners])
        notes = []
        ln_s2: np.ndarray | None = None
        if counts.min() < 2:
            notes.append("some design points have a single replicate: no dispersion (ln s²) "
                         "analysis")
        else:
            variances = np.array([values[g].var(ddof=1) for g in corners])
            if (variances <= 0).any():
                notes.append("some design points have identical replicates (s² = 0, ln s² "
                             "undefined): no dispersion analysis")
            else:
                ln_s2 = np.log(variances)
        if len(set(counts.tolist())) > 1:
            notes.append(f"unequal replicate counts {sorted(set(counts.tolist()))}: each design "
                         "point still weighs the same")
        centre_values = values[np.concatenate(centre)] if centre else np.empty(0)
        return cls(table.names, table.coded[[g[0] for g in corners]], means, ln_s2, counts,
                   f"replicates ({len(values)} rows) from {table.source}", centre_values, notes)

    @classmethod
    def from_summaries(cls, table: Table, mean_column: str, ln_s2_column: str | None = None,
                       s2_column: str | None = None) -> "RunData":
        """Per-run rows: the mean and either ln s² or s² (published summaries)."""
        if table.coded.shape[0] != len(group_runs(table.coded)):
            raise ProcessError(f"{table.source}: summary rows must be one per design point; "
                               "some points appear twice")
        corner = table.coded.any(axis=1)
        ln_s2 = None
        if ln_s2_column is not None:
            ln_s2 = table.columns[ln_s2_column][corner]
        elif s2_column is not None:
            s2 = table.columns[s2_column][corner]
            if (s2 <= 0).any():
                raise ProcessError(f"{table.source}: {s2_column} must be > 0 to take ln s²")
            ln_s2 = np.log(s2)
        return cls(table.names, table.coded[corner], table.columns[mean_column][corner], ln_s2,
                   np.ones(int(corner.sum()), dtype=int),
                   f"per-run summaries from {table.source}",
                   table.columns[mean_column][~corner])


@dataclass(frozen=True)
class Contrast:
    """One estimable contrast: its label, its aliases (word, sign) and its ±1 column."""

    label: str
    aliases: tuple[tuple[str, int], ...]
    column: np.ndarray

    def alias_text(self) -> str:
        return " = ".join([self.label] + [("-" if s < 0 else "") + w for w, s in self.aliases])


def contrasts(points: np.ndarray, names: Sequence[str]) -> tuple[list[Contrast], list[tuple[str, int]]]:
    """Alias classes of the design points and the defining relation [(word, sign)]."""
    runs, count = points.shape
    if count > MAX_ANALYSED_FACTORS:
        raise ProcessError(f"{count} factors: at most {MAX_ANALYSED_FACTORS} can be analysed")
    if not np.isin(points, (-1.0, 1.0)).all():
        raise ProcessError("design points must be coded -1 or +1 (centre points are kept apart)")
    classes: dict[bytes, list[tuple[str, int]]] = {}
    columns: dict[bytes, np.ndarray] = {}
    defining: list[tuple[str, int]] = []
    for size in range(1, count + 1):
        for combo in itertools.combinations(range(count), size):
            word = "".join(names[i] for i in combo)
            column = np.prod(points[:, combo], axis=1)
            if abs(column.sum()) == runs:
                defining.append((word, int(column[0])))
                continue
            sign = 1 if column[0] > 0 else -1
            key = (column * sign).astype(np.int8).tobytes()
            classes.setdefault(key, []).append((word, sign))
            columns.setdefault(key, column * sign)
    result = []
    for key, members in classes.items():
        label, label_sign = min(members, key=lambda m: label_key(m[0]))
        column = columns[key] * label_sign
        if column.sum() != 0:
            raise ProcessError(f"the design points are not balanced for {label} "
                               f"({int((column > 0).sum())} runs at +1, "
                               f"{int((column < 0).sum())} at -1): not a two-level factorial")
        aliases = tuple(sorted(((w, s * label_sign) for w, s in members if w != label),
                               key=lambda m: label_key(m[0])))
        result.append(Contrast(label, aliases, column))
    if len(result) != runs - 1:
        raise ProcessError(f"{runs} design points give {len(result)} independent contrasts, "
                           f"not {runs - 1}: the runs do not form a regular two-level "
                           "(fractional) factorial; is a run missing or repeated?")
    result.sort(key=lambda c: label_key(c.label))
    return result, sorted(defining, key=lambda d: label_key(d[0]))


def effects(values: np.ndarray, contrast_list: Sequence[Contrast]) -> dict[str, float]:
    """Effect of each contrast: mean at +1 minus mean at −1."""
    return {c.label: float(values[c.column > 0].mean() - values[c.column < 0].mean())
            for c in contrast_list}
