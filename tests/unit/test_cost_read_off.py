"""The coarse estimate reads evenly changing layers off the line between filled ones
(`paths/cost.subpart_cost(..., between)`): nearly the cost of filling every layer, for a
fraction of the fills, and never a layer whose section leaves the line (a step, a hole, a
second island)."""
from __future__ import annotations

import numpy as np
import pytest
from shapely.geometry import MultiPolygon, box

from freecad_conformal.geometry.frames import LayerFrame
from freecad_conformal.layers.model import Layer
from freecad_conformal.paths import cost
from freecad_conformal.paths.assemble import PathSettings
from freecad_conformal.paths.cost import Motion, subpart_cost
from freecad_conformal.paths.fill2d import FillSettings

HEIGHT = 0.2
MOTION = Motion(acceleration=800.0)
SETTINGS = PathSettings(fill=FillSettings(bead_width=0.4))
FILL = cost.layer_cost


def _stack(regions) -> list[Layer]:
    frame = LayerFrame.for_direction((0.0, 0.0, 1.0))
    return [Layer(subpart=0, index=i, frame=frame, section_height=HEIGHT * (i + 0.5),
                  region=MultiPolygon(list(getattr(r, "geoms", [r]))),
                  top_point=np.array([0.0, 0.0, HEIGHT * (i + 1)]),
                  top_normal=np.array([0.0, 0.0, 1.0]), thickness_min=HEIGHT,
                  thickness_max=HEIGHT)
            for i, r in enumerate(regions)]


def _taper(count: int = 40):
    """A wedge's sections: one side grows by a bead a layer, the area and outline evenly."""
    return [box(0.0, 0.0, 20.0 + 0.4 * i, 30.0) for i in range(count)]


def _costed(layers, between: int, monkeypatch) -> tuple[cost.SubPartCost, list[int]]:
    filled: list[int] = []

    def counted(layer, *args, **kwargs):
        filled.append(layer.index)
        return FILL(layer, *args, **kwargs)

    monkeypatch.setattr(cost, "layer_cost", counted)
    return subpart_cost(0, layers, SETTINGS, MOTION, False, between), filled


def test_an_even_taper_is_read_off_for_a_third_of_the_fills(monkeypatch):
    layers = _stack(_taper())
    every, all_filled = _costed(layers, 1, monkeypatch)
    quick, filled = _costed(layers, 3, monkeypatch)
    assert len(all_filled) == len(layers)
    assert len(filled) <= len(layers) // 2
    assert quick.seconds == pytest.approx(every.seconds, rel=0.005)
    assert quick.material == pytest.approx(every.material, rel=0.005)
    # Each layer read off keeps its own level (concurrent sub-parts are costed by level).
    # Rows alternate their angle from layer to layer, and a layer's cost with them (3 % of
    # the material on this taper; the time more where the rows' fewest-turns angle turns
    # as the taper widens): the line gives their mean, and the sum stays.
    for layer, read, full in zip(layers, quick.layers, every.layers):
        assert read.level == pytest.approx(layer.top_point[2])
        assert read.material == pytest.approx(full.material, rel=0.05)


def test_each_layer_read_off_takes_its_place_on_the_line(monkeypatch):
    """With a fill whose cost is the section's area, reading off is exact layer by layer."""
    def by_area(layer, *args, **kwargs):
        area = layer.region.area
        return cost.LayerCost(float(layer.top_point[2]), area, area, 0.0, area, area)

    monkeypatch.setattr(cost, "layer_cost", by_area)
    layers = _stack(_taper())
    quick = subpart_cost(0, layers, SETTINGS, MOTION, False, 3)
    assert [c.material for c in quick.layers] == pytest.approx(
        [layer.region.area for layer in layers], rel=1e-12)


def test_a_layer_read_off_lies_on_the_line_at_its_place():
    layer = _stack(_taper(3))[1]
    before = cost.LayerCost(0.2, 10.0, 8.0, 1.0, 30.0, 100.0)
    after = cost.LayerCost(0.8, 40.0, 38.0, 4.0, 60.0, 400.0)
    read = cost._read_off(layer, before, after, 1.0 / 3.0)
    assert (read.seconds, read.nominal_seconds, read.travel_nominal_seconds, read.material,
            read.length) == pytest.approx((20.0, 18.0, 2.0, 40.0, 200.0))
    assert read.level == pytest.approx(0.4)


@pytest.mark.parametrize("odd", ["hole", "island"])
def test_a_layer_off_the_line_is_filled(odd, monkeypatch):
    regions = _taper()
    middle = 20
    if odd == "hole":
        regions[middle] = regions[middle].difference(box(5.0, 5.0, 12.0, 25.0))
    else:
        regions[middle] = regions[middle].union(box(40.0, 0.0, 45.0, 30.0))
    layers = _stack(regions)
    every, _ = _costed(layers, 1, monkeypatch)
    quick, filled = _costed(layers, 3, monkeypatch)
    assert middle in filled
    assert quick.layers[middle].material == every.layers[middle].material
    assert quick.layers[middle].seconds == every.layers[middle].seconds
    assert quick.material == pytest.approx(every.material, rel=0.005)


def test_without_between_every_layer_is_filled(monkeypatch):
    layers = _stack(_taper(8))
    _, filled = _costed(layers, 1, monkeypatch)
    assert filled == list(range(8))
