"""The half-normal plot of the published line-curing study keeps both Lenth margins in view."""
from __future__ import annotations

import pytest

from tests.unit.test_doe_methods import from_summaries, published_analysis

matplotlib = pytest.importorskip("matplotlib")


def test_margins_are_inside_the_axes(tmp_path):
    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    from freecad_conformal.process.doe.plot import half_normal_panel, write_half_normal_png

    result = published_analysis(from_summaries())
    for name, margins, chosen in (("mean", result.lenth_mean, {"A", "D"}),
                                  ("ln_s2", result.lenth_ln_s2, {"B", "C", "D"})):
        axes = Figure().subplots()
        half_normal_panel(axes, result.half_normal(name), margins, chosen, name)
        low, high = axes.get_ylim()
        # with 7 contrasts SME is above every effect: it was drawn off the axes before
        assert margins.sme > max(result.half_normal(name).magnitudes)
        assert low <= margins.me < margins.sme < high
    path = tmp_path / "hn.png"
    write_half_normal_png(result, path)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
