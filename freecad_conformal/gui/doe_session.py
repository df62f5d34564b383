"""The DOE tab's state without Qt: a design from form fields, results typed in or imported,
the analysis, and "apply to tool". Every step calls the same process/ functions as the
`doe` command line; this module only turns form text into their arguments.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Sequence

import numpy as np

from freecad_conformal.errors import ProcessError
from freecad_conformal.fileio import write_text_atomic
from freecad_conformal.process.doe.analysis import Analysis, analyze
from freecad_conformal.process.doe.design import Design, Factor
from freecad_conformal.process.doe.effects import RunData
from freecad_conformal.process.doe.sheet import Table, read_table, run_sheet_text
from freecad_conformal.process.doe.to_tool import save_optimum
from freecad_conformal.process.library import ToolLibrary
from freecad_conformal.process.process_settings import ProcessSettings

GOALS = ("larger", "smaller", "nominal")
#: Drawn seeds stay below this so they read well in the form and in the saved design.
MAX_SEED = 1_000_000


@dataclass(frozen=True)
class FactorRow:
    """One row of the factor table as typed: levels are numbers or texts."""

    name: str
    label: str = ""
    low: str = "-1"
    high: str = "1"
    unit: str = ""

    def to_factor(self) -> Factor:
        low, high = _level(self.low), _level(self.high)
        if isinstance(low, float) != isinstance(high, float):
            raise ProcessError(f"factor {self.name}: both levels must be numbers or both texts, "
                               f"got {self.low!r} and {self.high!r}")
        return Factor(self.name.strip().upper(), self.label.strip(), low, high, self.unit.strip())


def _level(text: str) -> float | str:
    try:
        return float(text)
    except ValueError:
        return text.strip()


def parse_terms(text: str) -> Sequence[str] | str | None:
    """Model terms as the command line takes them: 'D,A', 'lenth', 'lenth-sme' or 'none'."""
    lowered = text.strip().lower()
    if lowered in ("", "none"):
        return None
    if lowered in ("lenth", "lenth-sme"):
        return lowered
    return [word.strip().upper() for word in text.split(",") if word.strip()]


def parse_generators(text: str) -> list[str]:
    """Generators separated by commas or spaces: 'D=ABC, E=-ABD' or 'I=ABCD'."""
    return [g for g in text.replace(",", " ").split() if g]


@dataclass
class DoeSession:
    """A study in progress: its design, the results entered per run, and the analysis."""

    design: Design | None = None
    results: list[float | None] = field(default_factory=list)
    imported: RunData | None = None
    analysis: Analysis | None = None

    def build_design(self, rows: Sequence[FactorRow], generators: str, replicates: int = 1,
                     centre_points: int = 0, seed: int | None = None,
                     response: str = "y") -> Design:
        """A new design from the form; clears results and analysis. Without a seed one is
        drawn and kept, so the run order stays the same for this study (sheet, results)."""
        factors = [row.to_factor() for row in rows]
        if seed is None:
            seed = int(np.random.SeedSequence().entropy % MAX_SEED)
        self.design = Design.build(factors, parse_generators(generators), replicates=replicates,
                                   centre_points=centre_points, seed=seed,
                                   response=response.strip() or "y")
        self.results = [None] * len(self.design.runs())
        self.imported = None
        self.analysis = None
        return self.design

    def load_design(self, path: str | Path) -> Design:
        """A design saved by `doe design --save` (or by `save_design`)."""
        try:
            data = json.loads(Path(path).read_text(encoding="utf-8"))
        except (OSError, json.JSONDecodeError) as exc:
            raise ProcessError(f"cannot read design {path}: {exc}") from exc
        self.design = Design.from_dict(data, f"design {Path(path).name}")
        if self.design.seed is None:  # fix the run order for this study
            self.design.seed = int(np.random.SeedSequence().entropy % MAX_SEED)
        self.results = [None] * len(self.design.runs())
        self.imported = self.analysis = None
        return self.design

    def save_design(self, path: str | Path) -> None:
        write_text_atomic(path, json.dumps(self._need_design().to_dict(), indent=2) + "\n")

    def _need_design(self) -> Design:
        if self.design is None:
            raise ProcessError("define the factors and generate the design first")
        return self.design

    def run_sheet(self) -> str:
        return run_sheet_text(self._need_design())

    def export_run_sheet(self, path: str | Path) -> None:
        write_text_atomic(path, self.run_sheet())

    def set_result(self, run_index: int, value: float | None) -> None:
        """The response of the run at `run_index` (0-based, in run order); None clears it."""
        if not 0 <= run_index < len(self.results):
            raise ProcessError(f"run {run_index + 1} is not in the run sheet "
                               f"({len(self.results)} runs)")
        self.results[run_index] = value
        self.imported = None

    def import_results(self, path: str | Path) -> RunData:
        """Results CSV with one row per replicate and the design's response column."""
        design = self._need_design()
        table = read_table(path, [design.response], design)
        self.imported = RunData.from_replicates(table, design.response)
        return self.imported

    def run_data(self) -> RunData:
        """The data to analyse: an imported file, else the values typed into the sheet."""
        if self.imported is not None:
            return self.imported
        design = self._need_design()
        missing = [i + 1 for i, v in enumerate(self.results) if v is None]
        if missing:
            shown = ", ".join(map(str, missing[:10])) + (" ..." if len(missing) > 10 else "")
            raise ProcessError(f"enter a result for every run; missing run(s) {shown}")
        # design.runs() is deterministic here: every session design has a seed
        coded = np.array([run.coded for run in design.runs()], dtype=float)
        table = Table(design.names, coded, {design.response: np.array(self.results, float)},
                      "results entered in the run sheet")
        return RunData.from_replicates(table, design.response)

    def analyze(self, location: str = "lenth", dispersion: str = "lenth", goal: str = "larger",
                target: float | None = None, response_scale: float | None = None,
                response_unit: str = "") -> Analysis:
        self.analysis = analyze(self.run_data(), parse_terms(location), parse_terms(dispersion),
                                goal=goal, target=target, design=self.design,
                                response_scale=response_scale, response_unit=response_unit)
        return self.analysis

    def effects_rows(self) -> list[tuple[str, str, float, float | None]]:
        """(effect, aliases, effect on the mean, effect on ln s²) for the effects table."""
        result = self._need_analysis()
        ln_s2 = result.effects_ln_s2 or {}
        return [(c.label, c.alias_text(), result.effects_mean[c.label], ln_s2.get(c.label))
                for c in result.contrasts]

    def _need_analysis(self) -> Analysis:
        if self.analysis is None:
            raise ProcessError("analyse the results first")
        return self.analysis

    def apply_to_tool(self, library: ToolLibrary, tool_id: str, material: str,
                      study: str = "") -> ProcessSettings:
        """Write the optimum into the tool's settings for `material` and save the library."""
        settings = save_optimum(library, tool_id, material, self._need_analysis(),
                                self.design, study)
        library.save()
        return settings
