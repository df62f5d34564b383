"""The check both path tests make: a stack's paths are, layer by layer, what each layer's
own `fill_layer` gives from where the last layer ended."""
from __future__ import annotations

import numpy as np

from freecad_conformal.paths import stack_fill
from freecad_conformal.paths.fill2d import fill_layer
from freecad_conformal.paths.map3d import air_at, map_paths


def assert_each_layers_own_fill(layers, skins, bridges, got, settings, position,
                                atol: float = 0.0) -> None:
    """`atol` (mm): how far a point may lie from the layer's own (0: bit for bit)."""
    tolerance = settings.fill.bead_width * stack_fill.SIMPLIFY_FRACTION
    for i, (layer, skin, bridge, paths) in enumerate(zip(layers, skins, bridges, got)):
        here = layer.frame.to_2d(position[None])[0]
        air = air_at(layers, i, bridge, settings.fill.bead_width)
        own = map_paths(layer, fill_layer(layer.region.simplify(tolerance), settings.fill,
                                          layer.index, skin, here, height=layer.thickness,
                                          bridge=bridge, air=air))
        assert [p.role for p in paths] == [p.role for p in own]
        assert all(a.points.shape == b.points.shape and np.allclose(a.points, b.points, rtol=0.0,
                                                                    atol=atol)
                   for a, b in zip(paths, own))
        position = own[-1].points[-1] if own else position
