"""Surface samples for the tool-envelope collision check (geometry/collision.surface_points)."""
from __future__ import annotations

import numpy as np
import pytest

from freecad_conformal.geometry import collision


@pytest.fixture(scope="module")
def twisted_loft(App, Part):
    """A solid lofted through three ellipses turning about its axis: B-spline sides curved
    both ways, as the fan's blades are."""
    wires = []
    for z, turn, (major, minor) in ((0.0, 0.0, (12.0, 3.0)), (10.0, 35.0, (9.0, 2.0)),
                                    (20.0, 70.0, (6.0, 1.5))):
        ellipse = Part.Ellipse(App.Vector(0, 0, z), major, minor)
        edge = ellipse.toShape()
        edge.rotate(App.Vector(0, 0, z), App.Vector(0, 0, 1), turn)
        wires.append(Part.Wire(edge))
    return Part.makeLoft(wires, True, False)


def test_samples_lie_on_the_surface_within_the_deflection(App, Part, twisted_loft):
    samples = collision.surface_points(twisted_loft, 1.0)
    rng = np.random.default_rng(7)
    picked = samples[rng.choice(len(samples), size=min(300, len(samples)), replace=False)]
    gaps = [twisted_loft.distToShape(Part.Vertex(App.Vector(*map(float, p))))[0] for p in picked]
    assert max(gaps) <= collision.SAMPLE_DEFLECTION + 1e-9


def test_every_point_of_the_surface_has_a_sample_within_the_spacing(twisted_loft):
    spacing = 1.0
    samples = collision.surface_points(twisted_loft, spacing)
    for face in twisted_loft.Faces:
        u0, u1, v0, v1 = face.ParameterRange
        for u in np.linspace(u0, u1, 17):
            for v in np.linspace(v0, v1, 17):
                point = face.valueAt(float(u), float(v))
                if not face.isInside(point, 1e-6, True):
                    continue
                nearest = np.min(np.linalg.norm(samples - np.array(tuple(point)), axis=1))
                assert nearest <= spacing, (face, u, v, nearest)


def test_the_shape_itself_keeps_its_own_mesh(App, Part):
    """The samples come from a copy: the shape's faces keep the triangulation other meshes
    of it share (a finer one left on them would be read back at any coarser deflection)."""
    shape = Part.makeCylinder(10.0, 20.0)
    _, before = shape.tessellate(1.0)
    collision.surface_points(shape, 1.0)
    _, after = shape.tessellate(1.0)
    assert len(after) == len(before)
