"""Acceptance test: the line-curing study of METHODS section 2, from the raw replicates and
from the published per-run summaries (ȳ, ln s²)."""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import pytest

from freecad_conformal.commands import doe as doe_command
from freecad_conformal.process.doe.analysis import analyze
from freecad_conformal.process.doe.design import Design
from freecad_conformal.process.doe.effects import RunData
from freecad_conformal.process.doe.sheet import read_table

DATA = Path(__file__).parent / "data"
REPLICATES = DATA / "line_curing_replicates.csv"
SUMMARIES = DATA / "line_curing_summaries.csv"
DESIGN = DATA / "line_curing_design.json"
RESPONSE = "speed_coefficient"
VMAX = 3.556  # mm/s, METHODS section 1

# Printed in METHODS section 2.
MEAN_EFFECTS = {"A": 0.2498, "B": -0.2216, "C": 0.1308, "D": 0.2802, "AB": -0.0848,
                "AC": 0.0806, "BC": -0.0458}
LN_S2_EFFECTS_PUBLISHED = {"A": 0.9009, "B": -2.1298, "C": -1.0330, "D": 1.8973, "AB": -0.9575,
                           "AC": -0.5677, "BC": -0.2966}
LN_S2_EFFECTS_RAW = {"A": 0.8832, "B": -2.2050, "C": -1.0562, "D": 1.9316, "AB": -0.9640,
                     "AC": -0.5445, "BC": -0.3309}
LOCATION = (0.44707, {"D": 0.14011, "A": 0.12489})
DISPERSION = (-8.7694, {"B": -1.0649, "D": 0.9487, "C": -0.5165})
OPTIMUM_COEFFICIENT = 0.71207
OPTIMUM_SPEED = 2.53  # mm/s, printed to two decimals

MEAN_TOL = 0.0005     # METHODS: effects on the mean ±0.0005 either way
LN_S2_TOL = 0.0003    # METHODS: ln s² effects ±0.0003 from the published column
# AC from the printed ln s² column is -0.56725, 0.00045 from the printed -0.5677: the column
# is rounded to 3 decimals (each effect can move by up to 8 x 0.0005 / 4 = 0.001), so the
# stated ±0.0003 cannot hold for AC; the rounding bound is used for it alone.
LN_S2_TOL_PUBLISHED = {**{k: LN_S2_TOL for k in LN_S2_EFFECTS_PUBLISHED}, "AC": 0.0005}


def from_replicates():
    table = read_table(REPLICATES, [RESPONSE])
    return RunData.from_replicates(table, RESPONSE)


def from_summaries():
    return RunData.from_summaries(read_table(SUMMARIES, ["ybar", "ln_s2"]), "ybar", "ln_s2")


def published_analysis(data):
    return analyze(data, location=["D", "A"], dispersion=["B", "D", "C"], goal="larger",
                   response_scale=VMAX, response_unit="mm/s")


@pytest.mark.parametrize("load", [from_replicates, from_summaries])
def test_effects_on_the_mean(load):
    result = published_analysis(load())
    assert set(result.effects_mean) == set(MEAN_EFFECTS)
    for label, expected in MEAN_EFFECTS.items():
        assert result.effects_mean[label] == pytest.approx(expected, abs=MEAN_TOL), label


def test_ln_s2_effects_from_the_published_column():
    result = published_analysis(from_summaries())
    for label, expected in LN_S2_EFFECTS_PUBLISHED.items():
        assert result.effects_ln_s2[label] == pytest.approx(
            expected, abs=LN_S2_TOL_PUBLISHED[label]), label


def test_ln_s2_effects_from_the_raw_replicates():
    result = published_analysis(from_replicates())
    for label, expected in LN_S2_EFFECTS_RAW.items():
        assert result.effects_ln_s2[label] == pytest.approx(expected, abs=LN_S2_TOL), label


@pytest.mark.parametrize("load", [from_replicates, from_summaries])
def test_location_model(load):
    model = published_analysis(load()).location
    assert model.intercept == pytest.approx(LOCATION[0], abs=MEAN_TOL)
    assert list(model.coefficients) == ["D", "A"]
    for term, expected in LOCATION[1].items():
        assert model.coefficients[term] == pytest.approx(expected, abs=MEAN_TOL / 2), term


def test_dispersion_model_from_the_published_column():
    model = published_analysis(from_summaries()).dispersion
    assert model.intercept == pytest.approx(DISPERSION[0], abs=LN_S2_TOL)
    for term, expected in DISPERSION[1].items():
        assert model.coefficients[term] == pytest.approx(expected, abs=LN_S2_TOL / 2), term


def test_dispersion_model_from_the_raw_replicates():
    """Coefficients are half the raw-replicate effects METHODS prints; the intercept is the
    mean ln s², recomputed here independently of the package."""
    model = published_analysis(from_replicates()).dispersion
    raw = np.loadtxt(REPLICATES, delimiter=",", skiprows=1, usecols=6).reshape(8, 3)
    assert model.intercept == pytest.approx(np.log(raw.var(axis=1, ddof=1)).mean(), abs=1e-12)
    for term in ("B", "D", "C"):
        assert model.coefficients[term] == pytest.approx(LN_S2_EFFECTS_RAW[term] / 2,
                                                         abs=LN_S2_TOL / 2), term


@pytest.mark.parametrize("load", [from_replicates, from_summaries])
def test_optimum_all_plus_at_2_53_mm_per_s(load):
    result = published_analysis(load())
    assert result.optimum.coded == {"A": 1.0, "B": 1.0, "C": 1.0, "D": 1.0}
    assert result.optimum.free == []
    # the sum of intercept and two coefficients: MEAN_TOL + 2 x MEAN_TOL/2
    assert result.optimum.mean == pytest.approx(OPTIMUM_COEFFICIENT, abs=2 * MEAN_TOL)
    assert round(result.predicted_real, 2) == OPTIMUM_SPEED


def test_optimum_in_real_units_with_the_design():
    design = Design.from_dict(json.loads(DESIGN.read_text()))
    data = RunData.from_replicates(read_table(REPLICATES, [RESPONSE], design), RESPONSE)
    result = analyze(data, ["D", "A"], ["B", "D", "C"], design=design)
    assert result.settings == {"A": 495.0, "B": 1.27, "C": "plastic film",
                               "D": "tool above the resin"}


def test_aliases_and_defining_relation_of_the_study():
    result = published_analysis(from_replicates())
    assert [("".join(w), s) for w, s in result.defining_relation] == [("ABCD", 1)]
    aliases = {c.label: c.alias_text() for c in result.contrasts}
    assert aliases == {"A": "A = BCD", "B": "B = ACD", "C": "C = ABD", "D": "D = ABC",
                       "AB": "AB = CD", "AC": "AC = BD", "BC": "BC = AD"}


def test_terms_may_be_named_by_an_alias():
    result = analyze(from_summaries(), location=["ABC", "BCD"], dispersion=None)
    assert list(result.location.coefficients) == ["D", "A"]


def run_doe(argv: list[str]) -> int:
    parser = argparse.ArgumentParser()
    doe_command.add_arguments(parser)
    return doe_command.run(parser.parse_args(argv))


@pytest.mark.parametrize("source", [
    [str(REPLICATES), "--response", RESPONSE],
    [str(SUMMARIES), "--mean", "ybar", "--ln-s2", "ln_s2"],
])
def test_cli_analyze_json(source, tmp_path, capsys):
    plot = tmp_path / "halfnormal.png"
    code = run_doe(["analyze", *source, "--location", "D,A", "--dispersion", "B,D,C",
                    "--response-scale", str(VMAX), "--response-unit", "mm/s",
                    "--plot", str(plot), "--json"])
    assert code == 0
    out = json.loads(capsys.readouterr().out)
    for label, expected in MEAN_EFFECTS.items():
        assert out["effects"]["mean"][label] == pytest.approx(expected, abs=MEAN_TOL)
    assert set(out["effects"]["ln_s2"]) == set(LN_S2_EFFECTS_RAW)
    assert out["models"]["location"]["coefficients"]["D"] == pytest.approx(0.14011, abs=MEAN_TOL / 2)
    assert set(out["models"]["dispersion"]["coefficients"]) == {"B", "D", "C"}
    assert out["optimum"]["coded"] == {"A": 1.0, "B": 1.0, "C": 1.0, "D": 1.0}
    assert round(out["optimum"]["predicted_real"], 2) == OPTIMUM_SPEED
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_cli_analyze_prints_the_effects_table(tmp_path, capsys):
    code = run_doe(["analyze", str(REPLICATES), "--design", str(DESIGN), "--location", "D,A",
                    "--dispersion", "B,D,C", "--response-scale", str(VMAX),
                    "--response-unit", "mm/s", "--plot", str(tmp_path / "p.png")])
    text = capsys.readouterr().out
    assert code == 0
    assert "AB = CD" in text and "-2.2050" in text and "0.2802" in text
    assert "495 mW" in text and "2.532 mm/s" in text
