"""Tool choice by curvature (METHODS section 1) with hand-computed limits."""
from __future__ import annotations

import argparse
import math

import pytest

from freecad_conformal.commands import tools as tools_command
from freecad_conformal.errors import ProcessError
from freecad_conformal.process.library import ToolLibrary
from freecad_conformal.process.selection import choose_tool, diameter_limits


@pytest.fixture(scope="module")
def tools(tmp_path_factory):
    return list(ToolLibrary.load(user_dir=tmp_path_factory.mktemp("user")))


def test_limits_by_hand():
    # rs 5, cd 0.5, θ 30°: 2·sqrt(0.5·9.5) = 4.3589; 2·4.5·0.5 = 4.5
    reach, rotation = diameter_limits(5.0, 0.5, math.radians(30))
    assert reach == pytest.approx(4.358899, abs=1e-6)
    assert rotation == pytest.approx(4.5)
    # rs 1, cd 0.1, θ 90°: 2·sqrt(0.1·1.9) = 0.87178; 2·0.9·1 = 1.8
    reach, rotation = diameter_limits(1.0, 0.1, math.pi / 2)
    assert reach == pytest.approx(0.871780, abs=1e-6)
    assert rotation == pytest.approx(1.8)
    assert diameter_limits(math.inf, 0.5, 0.3) == (math.inf, math.inf)


def test_largest_fitting_tool_is_recommended(tools):
    choice = choose_tool(tools, rs=5.0, cd=0.5, theta=math.radians(30))
    assert choice.recommended.id == "uv_large"          # straight preferred at equal size
    assert [t.id for t in choice.fitting] == ["uv_large", "uv_large_angled45", "uv_small"]


def test_small_curvature_needs_the_small_tool(tools):
    # rs 1, cd 0.1, θ 30°: reach 0.8718, rotation 2·0.9·0.5 = 0.9 -> only dt 0.3 fits
    choice = choose_tool(tools, rs=1.0, cd=0.1, theta=math.radians(30))
    assert choice.recommended.id == "uv_small"
    assert "cannot reach the curing depth" in choice.reasons["uv_large"]


def test_resolution_asked_picks_a_finer_tool(tools):
    choice = choose_tool(tools, rs=5.0, cd=0.5, theta=math.radians(30), resolution=0.5)
    assert choice.recommended.id == "uv_small"
    assert "wider than the resolution" in choice.reasons["uv_large"]
    assert {t.id for t in choice.fitting} >= {"uv_large", "uv_small"}


def test_tilt_beyond_w_needs_the_angled_tool(tools):
    choice = choose_tool(tools, rs=5.0, cd=0.5, theta=math.radians(80))
    assert choice.recommended.id == "uv_large_angled45"
    assert "outside the 0.0°..60.0°" in choice.reasons["uv_small"]


def test_nothing_fits_gives_reasons(tools):
    choice = choose_tool(tools, rs=0.2, cd=0.1, theta=math.radians(30))
    assert choice.recommended is None and choice.fitting == []
    text = choice.explanation()
    assert text.startswith("no tool fits: need dt <= 0.1 mm")
    assert "uv_small: dt 0.3 mm > 2(rs − cd)·sin θ = 0.1 mm" in text


def test_other_kinds_on_request(tools):
    choice = choose_tool(tools, rs=math.inf, cd=0.2, theta=math.radians(10), kind=None)
    assert choice.recommended.id == "endmill_6mm"


@pytest.mark.parametrize("rs, cd, theta, message", [
    (0.0, 0.1, 0.5, "rs must be > 0"),
    (1.0, 0.0, 0.5, "cd must be > 0"),
    (1.0, 1.5, 0.5, "must be smaller than the radius"),
    (1.0, 0.1, 4.0, "within"),
])
def test_impossible_inputs(rs, cd, theta, message):
    with pytest.raises(ProcessError, match=message):
        diameter_limits(rs, cd, theta)


def test_cli_choose(tmp_path, capsys):
    parser = argparse.ArgumentParser()
    tools_command.add_arguments(parser)
    args = parser.parse_args(["--user-dir", str(tmp_path), "choose", "--rs", "5", "--cd", "0.5",
                              "--theta", "80"])
    assert tools_command.run(args) == 0
    assert "recommended uv_large_angled45" in capsys.readouterr().out
    args = parser.parse_args(["--user-dir", str(tmp_path), "choose", "--rs", "0.2", "--cd",
                              "0.1", "--theta", "30"])
    assert tools_command.run(args) == 1


def test_fitting_tools_that_do_not_resolve_are_explained(tools):
    choice = choose_tool(tools, rs=5.0, cd=0.5, theta=math.radians(30), resolution=0.1)
    assert choice.recommended is None and choice.fitting
    assert choice.explanation().startswith("tools fit, but none resolves")
