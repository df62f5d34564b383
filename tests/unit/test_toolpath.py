"""Neutral toolpath: builder, validation errors, file round trip, summary metrics."""
from __future__ import annotations

import math

import numpy as np
import pytest

from freecad_conformal.post import samples
from freecad_conformal.toolpath import Toolpath, ToolpathBuilder, ToolpathError


def test_builder_normalises_axes_and_places_events():
    builder = ToolpathBuilder(part="p")
    builder.event("tool_change", tool=2)
    builder.add_segment([[0, 0, 0], [1, 0, 0]], axes=(0, 0, 2), kind="travel", feed=100)
    builder.event("light_on", power=0.5)
    builder.add_segment([[1, 0, 0], [2, 0, 0]], axes=[[0, 1, 1], [0, 0, 3]], kind="cure", feed=50)
    tp = builder.build()
    assert np.allclose(np.linalg.norm(tp.axes, axis=1), 1.0)
    assert tp.segment_index.tolist() == [0, 0, 1, 1]
    assert [(e.segment, e.position, e.action) for e in tp.events] == [
        (0, "before", "tool_change"), (0, "after", "light_on")]


@pytest.mark.parametrize("points, axes, message", [
    ([[0, 0, math.nan]], (0, 0, 1), "not finite at segment 0 point 0"),
    ([[0, 0, 0], [1, math.inf, 0]], (0, 0, 1), "not finite at segment 0 point 1"),
    ([[0, 0, 0], [1, 0, 0]], [[0, 0, 1], [0, 0, 0]], "zero or not finite at segment 0 point 1"),
])
def test_bad_values_name_segment_and_point(points, axes, message):
    builder = ToolpathBuilder()
    with pytest.raises(ToolpathError, match=message):
        builder.add_segment(points, axes)
        builder.build()


def test_empty_and_unknown_names_are_errors():
    with pytest.raises(ToolpathError, match="empty"):
        ToolpathBuilder().build()
    with pytest.raises(ToolpathError, match="unknown kind"):
        ToolpathBuilder().add_segment([[0, 0, 0]], kind="print")
    with pytest.raises(ToolpathError, match="unknown interpolation"):
        ToolpathBuilder().add_segment([[0, 0, 0]], interpolation="spline")
    builder = ToolpathBuilder()
    builder.add_segment([[0, 0, 0]])
    builder.event("laser_on", power=1.5)
    with pytest.raises(ToolpathError, match="power 1.5"):
        builder.build()


def test_save_load_round_trip(tmp_path):
    tp = samples.tilted_ring()
    path = tmp_path / "ring.npz"
    tp.save(path)
    back = Toolpath.load(path)
    for name in ("points", "axes", "segment_index", "kind", "feed", "tool", "flow", "interpolation"):
        assert np.array_equal(getattr(back, name), getattr(tp, name)), name
    assert back.events == tp.events and back.metadata == tp.metadata
    assert [p.name for p in tmp_path.iterdir()] == ["ring.npz"]


def test_load_errors(tmp_path):
    with pytest.raises(ToolpathError, match="does not exist"):
        Toolpath.load(tmp_path / "missing.npz")
    junk = tmp_path / "junk.npz"
    junk.write_bytes(b"not a zip")
    with pytest.raises(ToolpathError, match="not a Conformal toolpath"):
        Toolpath.load(junk)


def test_summary_lengths_volume_and_trapezoid_time():
    builder = ToolpathBuilder()
    builder.add_segment([[0, 0, 0], [30, 0, 0], [30, 40, 0]], kind="deposit", feed=600, flow=0.5)
    builder.add_segment([[30, 40, 0], [30, 40, 0.1]], kind="travel", feed=60)
    builder.event("dwell", seconds=2.0)
    summary = builder.build().summary(acceleration=100.0)
    assert summary.length_by_kind["deposit"] == pytest.approx(70.0)
    assert summary.length_by_kind["travel"] == pytest.approx(0.1)
    assert summary.material_volume == pytest.approx(35.0)
    # deposit: v = 10 mm/s reaches full speed (ramp 1 mm < 70 mm): 70/10 + 10/100;
    # travel: 0.1 mm is shorter than the 0.01 mm ramp? no: v = 1 mm/s, ramp 0.01 mm -> 0.1 + 0.01
    assert summary.time_s == pytest.approx(7.0 + 0.1 + 0.1 + 0.01 + 2.0)
    short = ToolpathBuilder()
    short.add_segment([[0, 0, 0], [0.5, 0, 0]], kind="cut", feed=600)
    assert short.build().summary(acceleration=100.0).time_s == pytest.approx(2 * math.sqrt(0.5 / 100))
