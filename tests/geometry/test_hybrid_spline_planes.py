"""Milling decisions treat a plane written as a B-spline (lofts, exporters, `toNurbs`) as
the plane it is (`face_normals.plane_normal`): the same "3+2" finishing axes, no ball
passes over it, and the same walls taken for flat ones, as the part made of planes."""
from __future__ import annotations

import numpy as np
import pytest

from freecad_conformal.decomposition.subparts import SubPart
from freecad_conformal.geometry import samples
from freecad_conformal.layers.model import LayerSettings
from freecad_conformal.layers.plan import plan_layers
from freecad_conformal.paths.ball_finish import finish_faces
from freecad_conformal.paths.hybrid import finishing_axes
from freecad_conformal.paths.hybrid_sequence import _flat_walls

UP = np.array([0.0, 0.0, 1.0])


@pytest.fixture(scope="module")
def branches():
    """The 45° branch and the same solid with every surface a B-spline."""
    branch = samples.branch45()
    splines = branch.toNurbs()
    assert {type(face.Surface).__name__ for face in splines.Faces} == {"BSplineSurface"}
    return branch, splines


def test_finishing_axes_and_ball_faces_are_those_of_the_planes(branches):
    branch, splines = branches
    planes = finishing_axes([branch], [UP], UP)
    assert len(planes) > 1                       # the leaning walls' own axes
    spline_axes = finishing_axes([splines], [UP], UP)
    assert len(spline_axes) == len(planes)
    assert all(np.allclose(a, b, atol=1e-9) for a, b in zip(planes, spline_axes))
    assert finish_faces(branch, [UP]) == [] and finish_faces(splines, [UP]) == []


def test_walls_taken_for_flat_are_those_of_the_planes(branches):
    branch, splines = branches
    sub = SubPart(index=0, shape=branch, build_direction=UP, volume=float(branch.Volume))
    stack = plan_layers(sub, LayerSettings(thickness=1.0))
    flat = [_flat_walls(branch, layer, stack, k) for k, layer in enumerate(stack)]
    assert any(flat)
    assert [_flat_walls(splines, layer, stack, k) for k, layer in enumerate(stack)] == flat
