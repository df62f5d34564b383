"""Two-level designs: generators, defining relation, aliases, resolution, runs, run sheets."""
from __future__ import annotations

import argparse
import csv
import io
import json

import numpy as np
import pytest

from freecad_conformal.commands import doe as doe_command
from freecad_conformal.errors import ProcessError
from freecad_conformal.process.doe.design import Design, Factor
from freecad_conformal.process.doe.sheet import read_table, run_sheet_text
from freecad_conformal.process.doe.words import multiply, parse_generators


def test_word_products_cancel_squares():
    assert multiply("AB", "BC") == "AC"
    assert multiply("ABCD", "ABCD") == ""
    assert multiply("I", "AB") == "AB"


def test_full_factorial_in_standard_order():
    design = Design.build(3, randomize=False)
    expected = np.array([[-1, -1, -1], [1, -1, -1], [-1, 1, -1], [1, 1, -1],
                         [-1, -1, 1], [1, -1, 1], [-1, 1, 1], [1, 1, 1]])
    assert np.array_equal(design.matrix(), expected)
    assert design.resolution is None
    assert len(design.alias_structure()) == 7
    assert all(not c.aliases for c in design.alias_structure())


@pytest.mark.parametrize("spec", [["D=ABC"], ["I=ABCD"], [" d = abc "]])
def test_half_fraction_from_a_generator_or_the_defining_relation(spec):
    design = Design.build(4, spec, randomize=False)
    matrix = design.matrix()
    assert matrix.shape == (8, 4)
    assert np.array_equal(matrix[:, 3], matrix[:, 0] * matrix[:, 1] * matrix[:, 2])
    assert design.defining_relation == [("ABCD", 1)]
    assert design.resolution == 4
    assert [str(a) for a in design.alias_structure()] == [
        "A = BCD", "B = ACD", "C = ABD", "D = ABC", "AB = CD", "AC = BD", "BC = AD"]


def test_negative_generator_gives_the_other_half():
    plus = Design.build(4, ["D=ABC"], randomize=False).matrix()
    minus = Design.build(4, ["I=-ABCD"], randomize=False).matrix()
    assert np.array_equal(minus[:, 3], -plus[:, 3])
    assert str(Design.build(4, ["D=-ABC"]).alias_structure()[0]) == "A = -BCD"


def test_quarter_fraction_relation_and_resolution():
    design = Design.build(6, ["E=ABC", "F=BCD"])
    assert set(design.defining_relation) == {("ABCE", 1), ("ADEF", 1), ("BCDF", 1)}
    assert design.resolution == 4
    assert design.point_count == 16
    same = Design.build(6, ["I=ABCE=BCDF"])
    assert np.array_equal(same.matrix(), design.matrix())


def test_resolution_three_design():
    design = Design.build(5, ["D=AB", "E=AC"])
    assert design.resolution == 3
    assert "D = AB = BCE = ACDE" in [str(a) for a in design.alias_structure()]


@pytest.mark.parametrize("spec, message", [
    (["D=ABD"], "must not repeat letters or contain D"),
    (["D=ABZ"], "unknown factor"),
    (["D=ABC", "D=AB"], "generated twice"),
    (["E=ABD", "D=ABC"], "list generators in order"),
    (["D==ABC"], "must look like"),
    (["I=AB"], "at least three"),
])
def test_bad_generators_are_rejected(spec, message):
    with pytest.raises(ProcessError, match=message):
        parse_generators(spec, "ABCDE")


def test_replicates_centre_points_and_seeded_order():
    factors = [Factor("A", "power", 231.0, 495.0, "mW"), Factor("B", "gap", 0.762, 1.27, "mm")]
    design = Design(factors, replicates=3, centre_points=2, seed=7)
    runs = design.runs()
    assert len(runs) == 4 * 3 + 2
    assert sorted(r.run_order for r in runs) == list(range(1, 15))
    assert sum(r.is_centre for r in runs) == 2
    assert [r.std_order for r in runs] == [r.std_order for r in Design(
        factors, replicates=3, centre_points=2, seed=7).runs()]
    assert [r.std_order for r in runs] != [r.std_order for r in Design(
        factors, replicates=3, centre_points=2, seed=8).runs()]
    counts = {}
    for r in runs:
        counts[r.std_order] = counts.get(r.std_order, 0) + 1
    assert counts == {1: 3, 2: 3, 3: 3, 4: 3, 5: 1, 6: 1}


def test_centre_points_need_numeric_factors():
    with pytest.raises(ProcessError, match="qualitative"):
        Design([Factor("A", low="film", high="resin"), Factor("B")], centre_points=1)


def test_run_sheet_holds_real_levels_and_reads_back():
    factors = [Factor("A", "power", 231.0, 495.0, "mW"), Factor("B", "gap", 0.762, 1.27, "mm"),
               Factor("C", "base", "cured resin", "plastic film")]
    design = Design(factors, replicates=2, seed=3, response="v")
    rows = list(csv.DictReader(io.StringIO(run_sheet_text(design))))
    assert len(rows) == 16
    assert {r["A"] for r in rows} == {"231", "495"}
    assert {r["C"] for r in rows} == {"cured resin", "plastic film"}
    assert all(r["v"] == "" for r in rows)
    assert [int(r["run_order"]) for r in rows] == list(range(1, 17))


def test_results_round_trip_recovers_known_effects(tmp_path):
    """Fill the run sheet from a known model and read it back: the effects come out exact."""
    from freecad_conformal.process.doe.analysis import analyze
    from freecad_conformal.process.doe.effects import RunData

    factors = [Factor("A", "power", 231.0, 495.0), Factor("B", "gap", 0.762, 1.27),
               Factor("C", "base", "cured resin", "plastic film"), Factor("D", "", 1.0, 3.0)]
    design = Design.build(factors, ["D=ABC"], replicates=2, seed=1, response="v")
    lines = run_sheet_text(design).splitlines()
    header = lines[0].split(",")
    filled = [lines[0]]
    for k, line in enumerate(lines[1:]):
        row = dict(zip(header, line.split(",")))
        x = {f.name: f.code(row[f.name]) for f in factors}
        noise = 0.01 if row["replicate"] == "1" else -0.01  # spread so ln s² exists
        row["v"] = repr(0.5 + 0.1 * x["A"] - 0.05 * x["C"] + 0.02 * x["A"] * x["B"] + noise)
        filled.append(",".join(row[h] for h in header))
    path = tmp_path / "results.csv"
    path.write_text("\n".join(filled) + "\n")
    result = analyze(RunData.from_replicates(read_table(path, ["v"], design), "v"), None, None)
    assert result.effects_mean["A"] == pytest.approx(0.2, abs=1e-9)
    assert result.effects_mean["C"] == pytest.approx(-0.1, abs=1e-9)
    assert result.effects_mean["AB"] == pytest.approx(0.04, abs=1e-9)
    assert result.effects_mean["B"] == pytest.approx(0.0, abs=1e-9)


def test_text_levels_need_the_design(tmp_path):
    path = tmp_path / "r.csv"
    path.write_text("A,B,y\nfilm,1,0.1\nresin,1,0.2\nfilm,-1,0.3\nresin,-1,0.4\n")
    with pytest.raises(ProcessError, match="pass the design file"):
        read_table(path, ["y"])


def test_missing_result_is_reported_with_its_line(tmp_path):
    path = tmp_path / "r.csv"
    path.write_text("A,B,y\n-1,-1,0.1\n1,-1,\n-1,1,0.3\n1,1,0.4\n")
    with pytest.raises(ProcessError, match="line 3: y = '' is not a number"):
        read_table(path, ["y"])


def test_incomplete_design_is_rejected(tmp_path):
    from freecad_conformal.process.doe.effects import RunData, contrasts

    path = tmp_path / "r.csv"
    path.write_text("A,B,C,y\n-1,-1,-1,1\n1,-1,-1,2\n-1,1,-1,3\n1,1,-1,4\n-1,-1,1,5\n")
    data = RunData.from_replicates(read_table(path, ["y"]), "y")
    with pytest.raises(ProcessError, match="not balanced|not form a regular"):
        contrasts(data.points, data.names)


def test_design_json_round_trip():
    design = Design.build([Factor("A", "p", 1.0, 2.0, "W"), Factor("B"), Factor("C"),
                           Factor("D", "s", "in", "above")], ["I=ABCD"], replicates=3, seed=5)
    again = Design.from_dict(json.loads(json.dumps(design.to_dict())))
    assert again.to_dict() == design.to_dict()
    assert np.array_equal(again.matrix(), design.matrix())


def run_doe(argv):
    parser = argparse.ArgumentParser()
    doe_command.add_arguments(parser)
    return doe_command.run(parser.parse_args(argv))


def test_cli_design_writes_sheet_and_design(tmp_path, capsys):
    sheet, saved = tmp_path / "runs.csv", tmp_path / "design.json"
    code = run_doe(["design", "--factor", "A:231:495:UV power:mW", "--factor", "B:0.762:1.27",
                    "--factor", "C:cured resin:plastic film", "--factor", "D:in:above",
                    "-g", "I=ABCD", "-r", "3", "--seed", "1", "--sheet", str(sheet),
                    "--save", str(saved)])
    out = capsys.readouterr().out
    assert code == 0
    assert "resolution IV" in out and "AB = CD" in out
    assert len(sheet.read_text().splitlines()) == 1 + 24
    assert Design.from_dict(json.loads(saved.read_text())).resolution == 4


def test_cli_design_json(capsys):
    assert run_doe(["design", "-k", "3", "--json", "--no-randomize"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["resolution"] is None and len(data["aliases"]) == 7


def test_real_levels_zero_and_one_are_not_taken_as_coded(tmp_path):
    path = tmp_path / "r.csv"
    path.write_text("A,B,y\n0,10,1\n1,10,2\n0,20,3\n1,20,4\n")
    table = read_table(path, ["y"])
    assert sorted(set(table.coded[:, 0])) == [-1.0, 1.0]
    assert sorted(set(table.coded[:, 1])) == [-1.0, 1.0]
