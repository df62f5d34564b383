"""Turning the command line's files, folders and globs into one job per part.

A STEP, BREP or IGES file is one part; an FCStd is one part per solid body (named
`file#Label`). An input that cannot become a job is not an error for the whole batch: it
becomes a failed report row with the reason, and the other parts still run.
"""
from __future__ import annotations

import glob
import os
import re
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Sequence

from freecad_conformal.jobs.batch.report import failed_row
from freecad_conformal.errors import GeometryError
from freecad_conformal.geometry.solids import SHAPE_SUFFIXES

FCSTD_SUFFIX = ".fcstd"

#: Characters kept in G-code file names; anything else (spaces, '#', '/') becomes '_'.
_UNSAFE_NAME = re.compile(r"[^A-Za-z0-9._-]+")


@dataclass(frozen=True)
class PartJob:
    """One part to plan.

    Attributes:
        index: position in the batch (the report keeps input order).
        part: the name shown in the report (`box.step`, `fixture.FCStd#Bracket`).
        path: the part file.
        body: internal object name of the body in an FCStd ("" for other files).
        body_label: its label in the tree ("" for other files).
        output: the G-code file name (no folder), unique within the batch.
        data: the file's bytes, for workers that cannot see `path` (remote Dask workers).
    """

    index: int
    part: str
    path: str
    body: str = ""
    body_label: str = ""
    output: str = ""
    data: bytes | None = field(default=None, repr=False)

    def with_data(self) -> "PartJob":
        """The same job carrying the file's bytes."""
        return replace(self, data=Path(self.path).read_bytes())


@dataclass
class Expansion:
    """The jobs to run and the rows of inputs that failed before running (both by index)."""

    jobs: list[PartJob]
    rejected: list[tuple[int, dict]]

    @property
    def total(self) -> int:
        return len(self.jobs) + len(self.rejected)


def _has_magic(text: str) -> bool:
    return any(char in text for char in "*?[")


def _is_part_file(path: Path) -> bool:
    return path.is_file() and path.suffix.lower() in SHAPE_SUFFIXES


def _files_of(item: str) -> tuple[list[Path], str | None]:
    """(files, reason none could be used) for one command line input."""
    if _has_magic(item):
        matches = sorted(Path(p) for p in glob.glob(os.path.expanduser(item), recursive=True))
        files = [p for p in matches if _is_part_file(p)]
        return files, None if files else (f"no part file ({', '.join(SHAPE_SUFFIXES)}) "
                                          f"matches {item!r}")
    path = Path(item).expanduser()
    if path.is_dir():
        files = sorted(p for p in path.iterdir() if _is_part_file(p))
        return files, None if files else f"folder {item} holds no part file"
    if not path.is_file():
        return [], f"part file not found: {item}"
    if path.suffix.lower() not in SHAPE_SUFFIXES:
        return [], (f"cannot read {path.name}: suffix {path.suffix.lower()!r} is not one of "
                    f"{', '.join(SHAPE_SUFFIXES)}")
    return [path], None


def _unique_output(stem: str, suffix: str, taken: set[str]) -> str:
    """`stem + suffix`, numbered when taken (compared case-blind for Windows and macOS)."""
    base = _UNSAFE_NAME.sub("_", stem).strip("._") or "part"
    name, count = f"{base}{suffix}", 1
    while name.lower() in taken:
        count += 1
        name = f"{base}_{count}{suffix}"
    taken.add(name.lower())
    return name


def expand_inputs(inputs: Sequence[str], suffix: str = ".gcode") -> Expansion:
    """One job per part in `inputs` (files, folders, globs); G-code names end with `suffix`.

    Opens each FCStd (FreeCAD needed) to list its solid bodies. A file named twice (by
    a glob and by name) is planned once.
    """
    jobs: list[PartJob] = []
    rejected: list[tuple[int, dict]] = []
    seen: set[Path] = set()
    taken: set[str] = set()
    for item in inputs:
        files, reason = _files_of(item)
        if reason is not None:
            rejected.append((len(jobs) + len(rejected), failed_row(item, item, reason)))
            continue
        for path in files:
            if path.resolve() in seen:
                continue
            seen.add(path.resolve())
            if path.suffix.lower() != FCSTD_SUFFIX:
                output = _unique_output(path.stem, suffix, taken)
                jobs.append(PartJob(len(jobs) + len(rejected), path.name, str(path), output=output))
                continue
            from freecad_conformal.jobs.batch.fcstd import solid_bodies

            try:
                bodies = solid_bodies(path)
            except GeometryError as exc:
                rejected.append((len(jobs) + len(rejected), failed_row(path.name, str(path), str(exc))))
                continue
            for body in bodies:
                output = _unique_output(f"{path.stem}_{body.label}", suffix, taken)
                jobs.append(PartJob(len(jobs) + len(rejected), f"{path.name}#{body.label}",
                                    str(path), body=body.name, body_label=body.label,
                                    output=output))
    return Expansion(jobs, rejected)
