"""Skins island by island: an island the layers around hold unchanged takes no Boolean."""
from __future__ import annotations

import numpy as np
import pytest
from shapely.geometry import MultiPolygon, Point, box

from freecad_conformal.geometry.frames import LayerFrame
from freecad_conformal.layers.model import Layer
from freecad_conformal.paths import map3d

Z = np.array([0.0, 0.0, 1.0])
FRAME = LayerFrame.for_direction(Z)
#: A mug's wall: the same ring on every layer, finely discretized as exact sections are.
RING = Point(0.0, 0.0).buffer(30.0, 256).difference(Point(0.0, 0.0).buffer(27.0, 256))


def _stack(handles: list[float | None]) -> list[Layer]:
    """One layer per entry: the ring, and beside it a handle of that width (None: none)."""
    layers = []
    for k, width in enumerate(handles):
        islands = [RING] if width is None else [RING, box(35.0, -width, 40.0, width)]
        layers.append(Layer(subpart=0, index=k, frame=FRAME, section_height=0.2 * k,
                            region=MultiPolygon(islands), top_point=0.2 * (k + 1) * Z,
                            top_normal=Z, thickness_min=0.2, thickness_max=0.2))
    return layers


def _whole(layers: list[Layer], i: int, top: int, bottom: int) -> MultiPolygon:
    """The skin of layer i by Booleans of whole regions (what skin_at made before)."""
    covered = layers[i].region
    for j in [*(i + k for k in range(1, top + 1)), *(i - k for k in range(1, bottom + 1))]:
        if not 0 <= j < len(layers):
            return layers[i].region
        covered = covered.intersection(layers[j].region)
    return layers[i].region.difference(covered)


def test_an_unchanged_island_takes_no_boolean_and_the_skins_are_the_whole_regions(monkeypatch):
    handles = [None, None, 2.0, 3.0, 3.0, 4.0, 2.5, None, None, None, 1.0, 1.5, None]
    layers = _stack(handles)
    seen: list = []
    real = map3d._boolean
    monkeypatch.setattr(map3d, "_boolean", lambda a, b, op: seen.append((a, b)) or real(a, b, op))
    skins = map3d.skin_regions(layers, 2, 2, rests_on_parent=False)
    assert seen, "the changing handle goes through GEOS"
    for a, b in seen:
        assert a.area < 0.5 * RING.area and b.area < 0.5 * RING.area
    for i, skin in enumerate(skins):
        expected = _whole(layers, i, 2, 2)
        assert skin.symmetric_difference(expected).area == pytest.approx(0.0, abs=1e-9), i
    # the ring is skin only within two layers of the bottom and of the top
    assert [skin.area > RING.area - 1e-6 for skin in skins] == \
        [True, True, False, False, False, False, False, False, False, False, False, True, True]


def test_islands_that_all_change_go_through_geos_whole(monkeypatch):
    layers = _stack([2.0, 3.0, 4.0, 5.0, 6.0])
    for layer, width in zip(layers, [27.0, 27.5, 28.0, 28.5, 29.0]):
        layer.region = MultiPolygon([Point(0, 0).buffer(width + 3.0, 64).difference(
            Point(0, 0).buffer(width, 64)), *list(layer.region.geoms)[1:]])
    seen: list = []
    real = map3d._boolean
    monkeypatch.setattr(map3d, "_boolean", lambda a, b, op: seen.append(op) or real(a, b, op))
    skins = map3d.skin_regions(layers, 1, 1, rests_on_parent=False)
    assert seen
    for i, skin in enumerate(skins):
        assert skin.symmetric_difference(_whole(layers, i, 1, 1)).area == pytest.approx(0.0,
                                                                                          abs=1e-9)
