"""Run sheets (CSV with real factor levels) out, results in: replicates or per-run summaries.

A results CSV has one column per factor, named by its letter (A, B, C, ...), holding coded
levels (−1/+1, 0 for centre points) or real levels; other columns (run order, notes) are
ignored. Real levels are coded with the design when one is given; without a design a numeric
column is coded by its smallest and largest value, and a text column is an error (which text
is the low level is not knowable from the sheet).
"""
from __future__ import annotations

import csv
import io
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from freecad_conformal.errors import ProcessError
from freecad_conformal.fileio import write_text_atomic
from freecad_conformal.process.doe.design import Design, Factor
from freecad_conformal.process.doe.words import FACTOR_LETTERS


def _format(value: float | str) -> str:
    return f"{value:.12g}" if isinstance(value, float) else str(value)


def run_sheet_text(design: Design) -> str:
    """The run sheet as CSV text: run order, standard order, replicate, real levels, and an
    empty response column to fill in."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(["run_order", "std_order", "replicate", *design.names, design.response])
    for run in design.runs():
        levels = [_format(f.real(x)) for f, x in zip(design.factors, run.coded)]
        writer.writerow([run.run_order, run.std_order, run.replicate, *levels, ""])
    return buffer.getvalue()


def write_run_sheet(design: Design, path: str | os.PathLike) -> None:
    write_text_atomic(path, run_sheet_text(design))


@dataclass
class Table:
    """Rows of a results CSV: coded factor levels and the named numeric columns."""

    names: list[str]
    coded: np.ndarray                 # rows × factors
    columns: dict[str, np.ndarray]    # requested value columns
    source: str


def _read_rows(path: str | os.PathLike) -> tuple[list[str], list[dict[str, str]]]:
    try:
        with open(path, newline="", encoding="utf-8-sig") as handle:
            reader = csv.DictReader(handle)
            rows = []
            for row in reader:
                if None in row:                  # DictReader files surplus values under None
                    raise ProcessError(f"results file {path}, line {reader.line_num}: more "
                                       f"values than the header's {len(reader.fieldnames or [])} "
                                       "columns")
                if any((v or "").strip() for v in row.values()):
                    rows.append(row)
            header = [h.strip() for h in (reader.fieldnames or [])]
    except OSError as exc:
        raise ProcessError(f"cannot read results file {path}: {exc.strerror or exc}") from exc
    except UnicodeDecodeError as exc:
        raise ProcessError(f"results file {path} is not UTF-8 text (byte {exc.start}: "
                           f"{exc.reason}); save it as CSV UTF-8") from None
    except csv.Error as exc:
        raise ProcessError(f"results file {path} is not a readable CSV: {exc}") from None
    repeated = sorted({h for h in header if h and header.count(h) > 1})
    if repeated:
        raise ProcessError(f"results file {path}: column(s) {', '.join(repeated)} appear more "
                           "than once in the header (which one holds the values?)")
    if not rows:
        raise ProcessError(f"results file {path} has no data rows")
    return header, [{(k or "").strip(): (v or "").strip() for k, v in row.items()} for row in rows]


def _infer_factor(name: str, values: list[str], where: str) -> Factor:
    """Coding for a factor column without a design: coded values as they are, else the
    smallest and largest number as the low and high level."""
    try:
        numbers = sorted({float(v) for v in values})
    except ValueError:
        raise ProcessError(f"{where}: column {name} holds text levels "
                           f"({', '.join(sorted(set(values)))}); pass the design file so they "
                           "can be coded") from None
    if {-1.0, 1.0} <= set(numbers) <= {-1.0, 0.0, 1.0}:
        return Factor(name, low=-1.0, high=1.0)
    if len(numbers) < 2:
        raise ProcessError(f"{where}: factor column {name} has a single level {numbers[0]:g}")
    return Factor(name, low=numbers[0], high=numbers[-1])


def _code_column(factor: Factor, values: list[str], where: str) -> np.ndarray:
    """Code a column that holds real levels, or coded levels (−1/0/+1) throughout."""
    try:
        return np.array([factor.code(v) for v in values])
    except ProcessError as real_error:
        try:
            numbers = {float(v) for v in values}
        except ValueError:
            raise ProcessError(f"{where}: {real_error}") from None
        if numbers <= {-1.0, 0.0, 1.0}:
            return np.array([float(v) for v in values])
        raise ProcessError(f"{where}: {real_error}") from None


def read_table(path: str | os.PathLike, value_columns: Sequence[str],
               design: Design | None = None) -> Table:
    """Read a results CSV; every row must hold a number in each of `value_columns`."""
    where = f"results file {Path(path).name}"
    header, rows = _read_rows(path)
    if design is not None:
        missing = [n for n in design.names if n not in header]
        if missing:
            raise ProcessError(f"{where}: no column for factor(s) {', '.join(missing)}")
        factors = design.factors
    else:
        names = [h for h in header if len(h) == 1 and h in FACTOR_LETTERS]
        if len(names) < 2:
            raise ProcessError(f"{where}: needs at least two factor columns named A, B, C, ...; "
                               f"found columns {', '.join(header)}")
        factors = [_infer_factor(n, [r[n] for r in rows], where) for n in names]
    for column in value_columns:
        if column not in header:
            raise ProcessError(f"{where}: no column {column!r} (columns: {', '.join(header)})")
    coded = np.column_stack([_code_column(f, [row[f.name] for row in rows], where)
                             for f in factors])
    values: dict[str, np.ndarray] = {}
    for column in value_columns:
        numbers = []
        for line, row in enumerate(rows, start=2):
            try:
                number = float(row[column])
            except ValueError:
                raise ProcessError(f"{where} line {line}: {column} = {row[column]!r} is not a "
                                   "number (every run needs a result)") from None
            if not math.isfinite(number):
                raise ProcessError(f"{where} line {line}: {column} = {row[column]!r} is not finite")
            numbers.append(number)
        values[column] = np.array(numbers)
    return Table([f.name for f in factors], coded, values, where)


def group_runs(coded: np.ndarray) -> list[np.ndarray]:
    """Row indices of each distinct design point, in order of first appearance (levels are
    exact here: `Factor.code` snaps them to −1, 0 or +1)."""
    groups: dict[tuple, list[int]] = {}
    for index, row in enumerate(coded):
        groups.setdefault(tuple(row), []).append(index)
    return [np.array(rows) for rows in groups.values()]
