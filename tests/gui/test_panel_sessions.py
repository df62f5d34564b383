"""The dock panel's logic without Qt: DOE session and tool library session."""
from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from freecad_conformal.errors import ProcessError
from freecad_conformal.gui.doe_session import DoeSession, FactorRow, parse_terms
from freecad_conformal.gui.tool_session import FormFields, ToolSession
from freecad_conformal.process.library import ToolLibrary

DATA = Path(__file__).resolve().parent.parent / "unit" / "data"


def line_curing_rows() -> list[FactorRow]:
    return [FactorRow("A", "UV power", "231", "495", "mW"), FactorRow("B", "gap", "0.762", "1.27", "mm"),
            FactorRow("C", "base", "cured resin", "plastic film"),
            FactorRow("D", "strategy", "tool in the resin", "tool above the resin")]


def test_design_from_form_rows_matches_the_saved_study():
    session = DoeSession()
    design = session.build_design(line_curing_rows(), "I=ABCD", replicates=3, seed=2024,
                                  response="speed_coefficient")
    saved = json.loads((DATA / "line_curing_design.json").read_text())
    assert design.to_dict()["factors"] == saved["factors"]
    assert design.point_count == 8 and len(session.results) == 24
    assert session.run_sheet().splitlines()[0] == (
        "run_order,std_order,replicate,A,B,C,D,speed_coefficient")


def test_typed_results_give_the_hand_computed_effects():
    session = DoeSession()
    design = session.build_design([FactorRow("A"), FactorRow("B"), FactorRow("C")], "")
    for index, run in enumerate(design.runs()):
        a, b, _ = run.coded
        session.set_result(index, 3.0 + 2.0 * a - 1.0 * b)   # effect = 2 x coefficient
    result = session.analyze(location="A,B", dispersion="none", goal="larger")
    effects = {label: mean for label, _, mean, _ in session.effects_rows()}
    assert effects["A"] == pytest.approx(4.0) and effects["B"] == pytest.approx(-2.0)
    assert effects["C"] == pytest.approx(0.0, abs=1e-12)
    assert result.optimum.coded["A"] == 1.0 and result.optimum.coded["B"] == -1.0
    assert result.optimum.mean == pytest.approx(6.0)


def test_missing_results_are_named():
    session = DoeSession()
    session.build_design([FactorRow("A"), FactorRow("B")], "")
    session.set_result(0, 1.0)
    with pytest.raises(ProcessError, match="missing run"):
        session.analyze()


def test_mixed_levels_are_rejected():
    with pytest.raises(ProcessError, match="both levels"):
        FactorRow("A", low="1", high="fast").to_factor()


def test_imported_results_reproduce_methods_and_apply_to_tool(tmp_path):
    session = DoeSession()
    session.load_design(DATA / "line_curing_design.json")
    session.import_results(DATA / "line_curing_replicates.csv")
    result = session.analyze("D,A", "B,D,C", "larger", response_scale=3.556,
                             response_unit="mm/s")
    assert result.predicted_real == pytest.approx(2.53, abs=0.005)
    library = ToolLibrary.load(user_dir=tmp_path)
    settings = session.apply_to_tool(library, "uv_small", "resin", "line curing")
    assert settings.feed == pytest.approx(result.predicted_real * 60.0)
    stored = ToolLibrary.load(user_dir=tmp_path).get("uv_small").settings["resin"]
    assert stored.feed == pytest.approx(settings.feed)
    assert stored.parameters["UV power [mW]"] == 495.0


def test_parse_terms_like_the_command_line():
    assert parse_terms("d, a") == ["D", "A"]
    assert parse_terms("Lenth") == "lenth" and parse_terms("none") is None


def test_tool_edit_duplicate_delete_persist(tmp_path):
    session = ToolSession.load(user_dir=tmp_path)
    text = session.tool_json("uv_small")
    tool = session.apply("uv_small", text, FormFields("uv_small", "Small guide", 0.3, 45.0))
    assert math.degrees(tool.max_tilt) == pytest.approx(45.0)
    assert (tmp_path / "uv_small.json").is_file()
    copy = session.duplicate("uv_small")
    assert copy.id == "uv_small_copy" and session.duplicate("uv_small").id == "uv_small_copy2"
    assert session.delete("uv_small_copy") == "deleted uv_small_copy"
    assert "shipped default is back" in session.delete("uv_small")
    reloaded = ToolSession.load(user_dir=tmp_path)
    rows = {row.id: row for row in reloaded.rows()}
    assert rows["uv_small"].origin == "default" and rows["uv_small"].max_tilt_deg == pytest.approx(60.0)
    assert "uv_small_copy2" in rows and "uv_small_copy" not in rows


def test_tool_validation_messages_name_the_problem(tmp_path):
    session = ToolSession.load(user_dir=tmp_path)
    with pytest.raises(ProcessError, match="line 1"):
        session.parse("{not json")
    bad = FormFields("uv_small", "x", 0.0, 30.0)
    with pytest.raises(ProcessError, match="diameter"):
        session.apply("uv_small", session.tool_json("uv_small"), bad)
    assert not (tmp_path / "uv_small.json").exists()


def test_tool_import_export_round_trip(tmp_path):
    session = ToolSession.load(user_dir=tmp_path / "user")
    exported = tmp_path / "two.json"
    session.export(exported, ["fdm_0p4", "uv_small"])
    other = ToolSession.load(user_dir=tmp_path / "other")
    with pytest.raises(ProcessError, match="already in"):
        other.import_file(exported)
    assert other.import_file(exported, replace=True) == ["fdm_0p4", "uv_small"]
    assert {r.id: r.origin for r in other.rows()}["fdm_0p4"] == "user"
