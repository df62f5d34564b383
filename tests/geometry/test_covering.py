"""Layers of a milled plan hold the whole part: sloped walls and tops included."""
from __future__ import annotations

import numpy as np
import pytest

from freecad_conformal.decomposition.subparts import SubPart
from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry.sections import PlanarSlicer
from freecad_conformal.layers.covering import covering_stack
from freecad_conformal.layers.model import LayerSettings, as_multipolygon
from freecad_conformal.layers.plan import plan_layers


def test_a_cone_is_held_slab_by_slab_and_to_its_tip():
    App, Part = import_freecad()
    cone = Part.makeCone(10.0, 2.0, 9.7)
    sub = SubPart(index=0, shape=cone, build_direction=np.array([0.0, 0.0, 1.0]))
    layers = plan_layers(sub, LayerSettings(thickness=0.5, tilt=False))
    # 19 slabs end at 9.5: the last 0.2 mm of the cone is not built additively
    assert float(layers[-1].top_point[2]) == pytest.approx(9.5)
    covered = covering_stack(sub, layers)
    assert len(covered) == len(layers) + 1 and float(covered[-1].top_point[2]) >= 9.7
    slicer = PlanarSlicer(cone, np.array([0.0, 0.0, 1.0]))
    for layer in covered[:-1]:
        bottom = float(layer.top_point[2]) - layer.thickness_max
        widest = as_multipolygon(slicer.section(bottom + 1e-3).polygons())
        # the slab's widest section (its foot: the cone narrows upwards) is deposited
        assert widest.difference(layer.region).area < 1e-6
        assert layer.region.area == pytest.approx(widest.area, rel=1e-6)
