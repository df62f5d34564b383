"""METHODS section 1's test cases, planned end to end, against the published figures."""
from __future__ import annotations

import pytest

from freecad_conformal.jobs import feature_examples as examples


@pytest.mark.slow
def test_published_examples(tmp_path, App):
    results = {e.name: e for e in examples.run(tmp_path)}
    cup = results["inverse conical cup, large tool"].toolpath
    # 2.3 mm wall at 0.4 mm/s (24 mm/min), first layer at half the feed
    assert sorted(set(cup.feed[cup.kind == 2].round(6))) == [12.0, 24.0]
    rods = results["rods on a sphere, small tool"].toolpath
    assert set(rods.feed[rods.kind == 2].round(6)) == {45.0}
    assert "16.0 s curing" in results["12 mm tilted rod"].ours
    assert results["fluidic channels on a cylinder"].toolpath.metadata["tools"] == \
        "T1 uv_large, T2 uv_small"
    assert "0.704·Vmax = 2.50 mm/s" in results["line-curing DOE (speed ∝ power)"].ours
    for name in ("flat_spiral", "inverse_conical_cup", "rods_on_a_sphere", "12_mm_tilted_rod",
                 "fluidic_channels_on_a_cylinder"):
        assert (tmp_path / f"{name}.png").stat().st_size > 10_000
    assert "| 12 mm tilted rod |" in (tmp_path / "examples.md").read_text()
