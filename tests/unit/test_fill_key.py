"""Layers the same but for rounding share one fill and one cost (`paths/stack_fill.fill_key`):
a layer's thickness is a difference of levels, and a turned part's sections carry the
turn's rounding. A square tube's 150 layers of one region were filled and costed one by
one (0.8 s of its 1.3 s plan)."""
from __future__ import annotations

import dataclasses

import numpy as np
import shapely
from shapely.geometry import MultiPolygon, Polygon, box

from freecad_conformal.geometry.frames import LayerFrame
from freecad_conformal.layers.model import Layer
from freecad_conformal.paths import cost, stack_fill
from freecad_conformal.paths.assemble import PathSettings
from freecad_conformal.paths.cost import Motion, subpart_cost
from freecad_conformal.paths.stack_fill import fill_key, stack_fills

#: The tube's two thicknesses of one 0.2 mm layer, as its levels' differences gave them.
NOISY_THICKNESSES = (0.19999999999999996, 0.20000000000000018)
#: A corner at 0 on one layer came at 1.5e-17 mm on another once the tube was turned over.
NOISE = 1.4547206236986674e-17


def _tube(shift: float = 0.0) -> MultiPolygon:
    """A 25 mm square tube's section, 1.2 mm walls (a gap between its loops), one corner
    moved by `shift`."""
    outer = [(shift, shift), (25.0, 0.0), (25.0, 25.0), (0.0, 25.0)]
    return MultiPolygon([Polygon(outer, [box(1.2, 1.2, 23.8, 23.8).exterior.coords])])


def _layer(index: int, region, thickness: float) -> Layer:
    frame = LayerFrame.for_direction((0.0, 0.0, 1.0))
    return Layer(subpart=0, index=index, frame=frame, section_height=0.2 * index + 0.1,
                 region=region, top_point=np.array([0.0, 0.0, 0.2 * (index + 1)]),
                 top_normal=np.array([0.0, 0.0, 1.0]), thickness_min=thickness,
                 thickness_max=thickness)


def _noisy_stack(count: int = 24) -> list[Layer]:
    """The tube's layers as a turned build gives them: one region but for 1e-17 mm at a
    corner, thicknesses off by rounding."""
    return [_layer(i, _tube(NOISE if i % 3 else -0.0), NOISY_THICKNESSES[i % 2 == 1 and i % 4 == 1])
            for i in range(count)]


def test_layers_the_same_but_for_rounding_have_one_key():
    first, second = NOISY_THICKNESSES
    a, b = _layer(2, _tube(-0.0), first), _layer(4, _tube(NOISE), second)
    assert shapely.to_wkb(a.region) != shapely.to_wkb(b.region) and a.thickness != b.thickness
    assert fill_key(a.region, None, None, a) == fill_key(b.region, None, None, b)


def test_layers_that_differ_have_other_keys():
    a = _layer(2, _tube(), 0.2)
    moved = _layer(2, _tube(1e-6), 0.2)           # a micrometre: another region
    thicker = _layer(2, _tube(), 0.2 + 1e-6)
    odd = _layer(3, _tube(), 0.2)                 # the other infill angle
    skin = box(0.0, 0.0, 25.0, 25.0)
    keys = {fill_key(a.region, None, None, a), fill_key(moved.region, None, None, moved),
            fill_key(thicker.region, None, None, thicker), fill_key(odd.region, None, None, odd),
            fill_key(a.region, skin, None, a), fill_key(a.region, None, skin, a)}
    assert len(keys) == 6


def test_a_stack_of_one_region_but_for_rounding_is_filled_once_per_kind(monkeypatch):
    made: list[int] = []
    original = stack_fill.layer_fill

    def counted(*args, **kwargs):
        made.append(args[2])
        return original(*args, **kwargs)

    monkeypatch.setattr(stack_fill, "layer_fill", counted)
    layers = _noisy_stack()
    fills = stack_fills([(layers, False)], PathSettings(), child=False)[0].fills
    # Bottom and top skins (three layers each) and the two infill angles between.
    assert len(made) <= 3 + 3 + 2
    assert len(fills) == len(layers) and all(fills)


def test_a_stack_of_one_region_but_for_rounding_is_costed_once_per_kind(monkeypatch):
    costed: list[int] = []
    original = cost.layer_cost

    def counted(layer, *args, **kwargs):
        costed.append(layer.index)
        return original(layer, *args, **kwargs)

    monkeypatch.setattr(cost, "layer_cost", counted)
    layers = _noisy_stack()
    found = subpart_cost(0, layers, PathSettings(), Motion(acceleration=800.0), False)
    assert len(costed) <= 3 + 3 + 2
    middle = [c for c in found.layers[3:-3]]
    assert all(dataclasses.astuple(c)[1:] == dataclasses.astuple(middle[i % 2])[1:]
               for i, c in enumerate(middle))


def test_distinct_fills_count_each_region_at_each_parity_to_rounding():
    """Whether a child fills layers meanwhile depends on how many distinct fills there are:
    a region at both parities is two (the infill turns), and the same region but for
    rounding is one. Regions alone counted a pipe tee's 103 fills as 42, and no child
    helped with them."""
    stack = _noisy_stack(24)
    assert stack_fill._distinct([(stack, False)]) == 2
    moved = [_layer(i, _tube(1e-3 * (i // 2)), 0.2) for i in range(24)]    # 12 regions
    assert stack_fill._distinct([(moved, False)]) == 24



def _fine_tube(shift: float = 0.0) -> MultiPolygon:
    """The tube with one corner rounded in many short chords, as a section comes (1 µm
    chord): simplifying it drops points. `shift` moves its first corner."""
    corner = [(22.0 + 3.0 * np.sin(t), 22.0 + 3.0 * np.cos(t))
              for t in np.linspace(0.0, 0.5 * np.pi, 200)]
    outer = [(shift, 0.0), (25.0, 0.0), *corner[::-1], (0.0, 25.0)]
    return MultiPolygon([Polygon(outer, [box(1.2, 1.2, 23.8, 23.8).exterior.coords])])


def test_a_prisms_region_is_simplified_once_and_each_other_region_its_own(monkeypatch):
    """A prism's layers repeat one region bit for bit (the table's 300 layers hold 7):
    simplified once, and each layer filled from it. A region that differs, however
    little, is simplified itself."""
    regions = [_fine_tube(), _fine_tube(1e-3)]
    layers = [_layer(i, regions[i // 10], 0.2) for i in range(20)]
    simplified: list[int] = []
    original = MultiPolygon.simplify
    monkeypatch.setattr(MultiPolygon, "simplify",
                        lambda self, *args, **kwargs: simplified.append(1) or original(self, *args, **kwargs))
    filled: list = []
    monkeypatch.setattr(stack_fill, "layer_fill",
                        lambda region, *args, **kwargs: filled.append(region) or [])
    stack_fills([(layers, False)], PathSettings(), child=False)
    assert len(simplified) == 2
    monkeypatch.undo()
    tolerance = PathSettings().fill.bead_width * stack_fill.SIMPLIFY_FRACTION
    expected = [shapely.to_wkb(region.simplify(tolerance)) for region in regions]
    assert shapely.get_num_coordinates(regions[0].simplify(tolerance)) < 100
    # Each distinct fill made from its own layer's region simplified: both regions'.
    assert {shapely.to_wkb(region) for region in filled} == set(expected)
