"""Point-in-solid many at once: the mesh's ray parity against the exact answer."""
from __future__ import annotations

import numpy as np

from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry.inside import DEFLECTION, MeshInside, inside_test


def test_mesh_parity_agrees_with_the_sphere_and_a_hollow_box_off_the_surface():
    App, Part = import_freecad()
    rng = np.random.default_rng(7)
    sphere = Part.makeSphere(10.0)
    points = rng.uniform(-12, 12, size=(20000, 3))
    radius = np.linalg.norm(points, axis=1)
    clear = np.abs(radius - 10.0) > 2 * DEFLECTION
    assert (MeshInside(sphere)(points)[clear] == (radius < 10.0)[clear]).all()
    # a box with a box-shaped void: rays cross four faces, two, or none
    hollow = Part.makeBox(20, 20, 20).cut(Part.makeBox(10, 10, 10, App.Vector(5, 5, 5)))
    points = rng.uniform(-2, 22, size=(20000, 3))
    exact = np.array([hollow.isInside(App.Vector(*p), 1e-9, True) for p in points])
    assert (MeshInside(hollow)(points) == exact).all()


def test_the_exact_classifier_serves_within_its_budget_and_the_mesh_beyond():
    App, Part = import_freecad()
    box = Part.makeBox(10, 10, 10)
    points = np.array([[5.0, 5.0, 10.0], [5.0, 5.0, 5.0], [5.0, 5.0, 11.0]])
    # only OCC tells a point on the surface apart (the flag): so it is OCC here
    exact = inside_test(box, budget=float("inf"))
    assert exact(points, True).tolist() == [True, True, False]
    assert exact(points, False).tolist() == [False, True, False]
    # no call is free: the mesh, whose answer does not depend on the flag
    mesh = inside_test(box, budget=0.0)
    assert mesh(points, True).tolist() == mesh(points, False).tolist()
    assert mesh(points, True)[1:].tolist() == [True, False]
