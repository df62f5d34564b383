"""Statistics, term selection, optimum goals, the plot and saving a setting into a tool."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from freecad_conformal.errors import ProcessError
from freecad_conformal.process.doe.analysis import analyze
from freecad_conformal.process.doe.design import Design
from freecad_conformal.process.doe.effects import RunData
from freecad_conformal.process.doe.models import Model, find_optimum
from freecad_conformal.process.doe.sheet import Table
from freecad_conformal.process.doe.stats import half_normal_quantiles, lenth, t_quantile

DATA = Path(__file__).parent / "data"


@pytest.mark.parametrize("p, dof, expected", [
    (0.975, 1, 12.706), (0.975, 2, 4.303), (0.975, 5, 2.571), (0.975, 30, 2.042),
    (0.95, 10, 1.812),                      # Student's t table, 3 decimals
    (0.975, 7 / 3, 3.764),                  # Lenth (1989): ME factor for m = 7 contrasts
])
def test_t_quantile_matches_tables(p, dof, expected):
    assert t_quantile(p, dof) == pytest.approx(expected, abs=6e-4)
    assert t_quantile(1 - p, dof) == pytest.approx(-expected, abs=6e-4)


def test_t_quantile_matches_scipy_where_installed():
    stats = pytest.importorskip("scipy.stats", reason="scipy not installed: table test covers it")
    for p in (0.6, 0.9, 0.99, 0.9995):
        for dof in (0.7, 7 / 3, 5, 14 / 3, 40):
            assert t_quantile(p, dof) == pytest.approx(stats.t.ppf(p, dof), rel=1e-8)


def test_lenth_on_hand_values():
    # |c| = 1..6 and 20: median 4 -> s0 6; 20 >= 15 is trimmed -> PSE 1.5 x median(1..6) = 5.25
    margins = lenth([1, -2, 3, -4, 5, 6, 20])
    assert margins.pse == pytest.approx(5.25)
    assert margins.me == pytest.approx(5.25 * t_quantile(0.975, 7 / 3))
    gamma = 0.5 * (1 + 0.95 ** (1 / 7))
    assert margins.sme == pytest.approx(5.25 * t_quantile(gamma, 7 / 3))
    assert margins.sme / margins.pse == pytest.approx(9.0, abs=0.02)  # Lenth's table: 9.01


def test_half_normal_quantiles():
    q = half_normal_quantiles(7)
    assert q[3] == pytest.approx(0.6745, abs=1e-4)  # Φ⁻¹(0.75): the median of |N(0,1)|
    assert np.all(np.diff(q) > 0)


def synthetic(effects: dict[str, float], noise_seed: int = 0, replicates: int = 2) -> RunData:
    """A 2^4 full factorial with known effects and small noise."""
    design = Design.build(4, randomize=False)
    points = np.repeat(design.matrix(), replicates, axis=0)
    rng = np.random.default_rng(noise_seed)
    y = 10 + rng.normal(0, 0.05, len(points))
    for word, effect in effects.items():
        y += effect / 2 * np.prod([points[:, "ABCD".index(c)] for c in word], axis=0)
    table = Table(list("ABCD"), points, {"y": y}, "synthetic")
    return RunData.from_replicates(table, "y")


def test_lenth_selects_the_active_effects():
    result = analyze(synthetic({"A": 3.0, "C": -2.0, "BD": 1.5}), location="lenth",
                     dispersion=None)
    assert set(result.location.coefficients) == {"A", "C", "BD"}
    assert result.location.coefficients["C"] == pytest.approx(-1.0, abs=0.05)


def test_no_effect_selected_gives_a_grand_mean_model_and_a_note():
    result = analyze(synthetic({}), location="lenth-sme", dispersion=None)
    assert result.location.coefficients == {}
    assert result.location.intercept == pytest.approx(10, abs=0.05)
    assert any("grand mean" in n for n in result.notes)
    assert result.optimum.free == list("ABCD")


def test_unknown_term_is_rejected_with_the_estimable_list():
    with pytest.raises(ProcessError, match="not estimable"):
        analyze(synthetic({"A": 1}), location=["AE"], dispersion=None)


def test_single_replicates_give_no_dispersion():
    data = synthetic({"A": 1}, replicates=1)
    assert data.ln_s2 is None
    result = analyze(data, ["A"], "lenth")
    assert result.dispersion is None and result.effects_ln_s2 is None
    with pytest.raises(ProcessError, match="no replicate variance"):
        analyze(data, ["A"], ["B"])


def test_smaller_the_better_uses_dispersion_to_break_ties():
    location = Model(1.0, {"A": 0.3})
    dispersion = Model(-5.0, {"B": 0.8, "A": 0.1})
    optimum = find_optimum(list("ABC"), location, dispersion, "smaller")
    assert optimum.coded == {"A": -1.0, "B": -1.0, "C": -1.0}
    assert optimum.free == ["C"]
    assert optimum.mean == pytest.approx(0.7)
    assert optimum.ln_s2 == pytest.approx(-5.9)


def test_nominal_the_better_hits_the_target_with_a_numeric_factor():
    location = Model(1.0, {"A": 0.5, "B": 0.2})
    dispersion = Model(-6.0, {"B": -1.0})
    optimum = find_optimum(list("AB"), location, dispersion, "nominal", target=1.1,
                           numeric=["A"])
    assert optimum.coded["B"] == 1.0            # lowest variance
    assert optimum.coded["A"] == pytest.approx(-0.2, abs=0.005)   # 1 + 0.5·xA + 0.2 = 1.1
    assert optimum.mean == pytest.approx(1.1, abs=0.003)
    with pytest.raises(ProcessError, match="target"):
        find_optimum(list("AB"), location, dispersion, "nominal")


def test_half_normal_png_is_written(tmp_path):
    from freecad_conformal.process.doe.plot import write_half_normal_png

    result = analyze(synthetic({"A": 3.0}), "lenth", "lenth")
    path = tmp_path / "hn.png"
    write_half_normal_png(result, path)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert path.stat().st_size > 5000


def test_optimum_saved_into_a_tool(tmp_path):
    from freecad_conformal.process.doe.sheet import read_table
    from freecad_conformal.process.doe.to_tool import save_optimum
    from freecad_conformal.process.library import ToolLibrary

    design = Design.from_dict(json.loads((DATA / "line_curing_design.json").read_text()))
    data = RunData.from_replicates(
        read_table(DATA / "line_curing_replicates.csv", ["speed_coefficient"], design),
        "speed_coefficient")
    result = analyze(data, ["D", "A"], ["B", "D", "C"], design=design, response_scale=3.556,
                     response_unit="mm/s")
    library = ToolLibrary.load(user_dir=tmp_path)
    settings = save_optimum(library, "uv_large", "resin", result, design, "line curing")
    assert settings.feed == pytest.approx(result.predicted_real * 60)
    assert settings.parameters["UV power [mW]"] == 495.0
    assert settings.parameters["base"] == "plastic film"
    library.save()
    again = ToolLibrary.load(user_dir=tmp_path)
    assert again.origin("uv_large") == "user"
    assert again.get("uv_large").settings["resin"].feed == pytest.approx(settings.feed)
    result.response_unit = "mW"
    with pytest.raises(ProcessError, match="not a speed"):
        save_optimum(library, "uv_large", "resin", result, design)


def test_design_matches_pydoe3_where_installed():
    """Cross-check against pyDOE3 (optional; the design tests above do not depend on it)."""
    pydoe = pytest.importorskip("pyDOE3", reason="pyDOE3 not installed (optional cross-check)")
    for k in (2, 3, 5):
        mine = {tuple(row) for row in Design.build(k).matrix()}
        assert mine == {tuple(row) for row in pydoe.ff2n(k)}
    for generators, pattern in ((["D=ABC"], "a b c abc"), (["E=ABC", "F=BCD"], "a b c d abc bcd"),
                                (["D=-AB"], "a b c -ab")):
        k = len(pattern.split())
        mine = {tuple(row) for row in Design.build(k, generators).matrix()}
        assert mine == {tuple(row) for row in pydoe.fracfact(pattern)}


def test_cli_saves_the_optimum_into_the_user_library(tmp_path, capsys):
    import argparse

    from freecad_conformal.commands import doe as doe_command
    from freecad_conformal.process.library import ToolLibrary

    parser = argparse.ArgumentParser()
    doe_command.add_arguments(parser)
    args = parser.parse_args([
        "analyze", str(DATA / "line_curing_replicates.csv"), "--design",
        str(DATA / "line_curing_design.json"), "--location", "D,A", "--dispersion", "B,D,C",
        "--response-scale", "3.556", "--response-unit", "mm/s", "--no-plot",
        "--save-tool", "uv_small", "--material", "resin", "--user-dir", str(tmp_path)])
    assert doe_command.run(args) == 0
    saved = ToolLibrary.load(user_dir=tmp_path).get("uv_small").settings["resin"]
    assert saved.feed / 60 == pytest.approx(2.53, abs=0.005)
    assert saved.parameters["strategy"] == "tool above the resin"
