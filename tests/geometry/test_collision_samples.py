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


def test_a_shape_meshed_already_is_sampled_from_that_mesh(App, Part, twisted_loft, monkeypatch):
    """The decomposition's mesh of a sub-part is sampled, not a second one made, and its
    samples lie on the surface within that mesh's chord error."""
    from freecad_conformal.geometry.surface_mesh import surface_mesh

    shape = twisted_loft.copy()
    mesh = surface_mesh(shape)
    assert mesh is not None and mesh.deflection <= collision.REUSED_DEFLECTION

    def meshed_again(_shape):
        raise AssertionError("a second mesh was made")

    monkeypatch.setattr(collision, "_triangulated", meshed_again)
    samples = collision.surface_points(shape, 1.0)
    assert len(samples) >= len(mesh.points)
    rng = np.random.default_rng(11)
    picked = samples[rng.choice(len(samples), size=200, replace=False)]
    gaps = [shape.distToShape(Part.Vertex(App.Vector(*map(float, p))))[0] for p in picked]
    assert max(gaps) <= mesh.deflection + 1e-9


def test_a_coarse_mesh_of_the_shape_is_not_sampled(App, Part, monkeypatch):
    """A mesh whose chord error could hide a collision (a large part's) is left alone: the
    samples come from a copy meshed at SAMPLE_DEFLECTION."""
    from freecad_conformal.geometry.surface_mesh import surface_mesh

    shape = Part.makeCylinder(150.0, 300.0)
    mesh = surface_mesh(shape)
    assert mesh is not None and mesh.deflection > collision.REUSED_DEFLECTION
    copies = []
    real = collision._triangulated
    monkeypatch.setattr(collision, "_triangulated", lambda s: copies.append(s) or real(s))
    samples = collision.surface_points(shape, 5.0)
    assert copies
    gaps = [shape.distToShape(Part.Vertex(App.Vector(*map(float, p))))[0] for p in samples[::50]]
    assert max(gaps) <= collision.SAMPLE_DEFLECTION + 1e-9


def test_a_rigid_copy_of_a_meshed_shape_is_sampled_from_that_mesh_moved(App, Part, twisted_loft,
                                                                        monkeypatch):
    """A sub-part laid out on the platform (turned and moved: decomposition/layout.py) is
    sampled from its original's mesh carried along, its samples on the copy's surface."""
    from freecad_conformal.geometry.solids import moved_rigidly
    from freecad_conformal.geometry.surface_mesh import made_mesh, surface_mesh

    shape = twisted_loft.copy()
    mesh = surface_mesh(shape)
    moved = shape.copy()
    moved.rotate(App.Vector(1, 2, 3), App.Vector(0, 1, 0), 90)
    moved.translate(App.Vector(50, 0, 10))
    moved_rigidly(shape, moved)
    monkeypatch.setattr(collision, "_triangulated",
                        lambda _s: (_ for _ in ()).throw(AssertionError("meshed again")))
    samples = collision.surface_points(moved, 1.0)
    rng = np.random.default_rng(5)
    picked = samples[rng.choice(len(samples), size=200, replace=False)]
    gaps = [moved.distToShape(Part.Vertex(App.Vector(*map(float, p))))[0] for p in picked]
    assert max(gaps) <= mesh.deflection + 1e-9
    # The normals turn with it: outward from the copy's axis, which now runs along X.
    carried = made_mesh(moved)
    centre = np.array(tuple(moved.BoundBox.Center))
    sides = carried.points[carried.triangles[:, 0]] - centre
    sides[:, 0] = 0.0
    assert np.mean(np.einsum("ij,ij->i", carried.normals[:, 0, :], sides) > 0) > 0.9


def test_a_copy_not_only_moved_gets_no_mesh(App, Part):
    from freecad_conformal.geometry.solids import moved_rigidly
    from freecad_conformal.geometry.surface_mesh import made_mesh, surface_mesh

    shape = Part.makeBox(10, 10, 10)
    surface_mesh(shape)
    scaled = shape.copy()
    scaled.scale(2.0)
    moved_rigidly(shape, scaled)
    assert made_mesh(scaled) is None
