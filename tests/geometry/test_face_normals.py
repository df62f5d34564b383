"""Exact normals at a curved face's tessellation nodes (geometry/face_normals.py)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from freecad_conformal.geometry import samples


def _bump(App, Part):
    """A smooth B-spline patch (no seam, no crease) over 20 x 20 mm."""
    grid = [[App.Vector(x, y, 2.0 * math.sin(x / 6.0) * math.cos(y / 7.0))
             for y in np.linspace(0.0, 20.0, 6)] for x in np.linspace(0.0, 20.0, 6)]
    surface = Part.BSplineSurface()
    surface.interpolate(grid)
    return surface.toShape()


def test_nodes_off_their_uv_points_take_their_own_uv_nodes_normal(App, Part):
    """BRepMesh puts an edge's nodes on its 3D curve and their UV on its pcurve, up to the
    edge's tolerance apart: such a node takes the normal of its own UV node, exactly as a
    node found by position does (projecting each back cost 0.6 ms a node)."""
    from freecad_conformal.geometry.face_normals import node_normals

    face = _bump(App, Part)
    face.fixTolerance(1e-5)
    points, triangles = face.tessellate(0.05)
    p = np.array([tuple(v) for v in points])
    t = np.asarray(triangles, dtype=int)
    found = node_normals(face, p, t)
    # Every node 5e-6 mm off: none is found by position, each within twice the tolerance.
    rng = np.random.default_rng(7)
    offset = rng.normal(size=p.shape)
    offset *= 5e-6 / np.linalg.norm(offset, axis=1)[:, None]
    assert np.array_equal(node_normals(face, p + offset, t), found)
    # Nodes farther off than that are projected back: the same normals, to rounding.
    far = node_normals(face, p + 40.0 * offset, t)
    assert np.allclose(far, found, atol=1e-4) and not np.array_equal(far, found)


def test_a_planar_faces_normal_is_read_once_and_follows_its_orientation(App, Part):
    """Cached by face: the same face (and the same face found again in its solid) gives the
    same read-only array, its reversed twin and a moved copy their own; a curved face
    none."""
    import pytest

    from freecad_conformal.geometry.face_normals import plane_normal

    box = Part.makeBox(10, 10, 10)
    bottom = next(f for f in box.Faces if f.CenterOfMass.z < 1e-9)
    first = plane_normal(bottom)
    np.testing.assert_allclose(first, [0.0, 0.0, -1.0], atol=1e-12)
    again = next(f for f in box.Faces if f.CenterOfMass.z < 1e-9)
    assert plane_normal(again) is first
    with pytest.raises(ValueError):
        first[2] = 1.0
    np.testing.assert_allclose(plane_normal(bottom.reversed()), [0.0, 0.0, 1.0], atol=1e-12)
    turned = box.copy()
    turned.rotate(App.Vector(0, 0, 0), App.Vector(1, 0, 0), 90.0)
    moved = next(f for f in turned.Faces if abs(f.CenterOfMass.y) < 1e-9)
    np.testing.assert_allclose(plane_normal(moved), [0.0, 1.0, 0.0], atol=1e-12)
    assert plane_normal(Part.makeCylinder(2.0, 5.0).Faces[0]) is None


def test_a_planar_b_spline_face_has_its_planes_normal_and_a_curved_one_none(App, Part):
    from freecad_conformal.geometry.face_normals import plane_normal

    prism = samples.oblique_prism()
    sides = [f for f in prism.Faces if type(f.Surface).__name__ == "BSplineSurface"]
    assert len(sides) == 4
    for face in sides:
        normal = plane_normal(face)
        assert normal is not None
        # the normal is the face's own, outward, at every point of it
        u0, u1, v0, v1 = face.ParameterRange
        for u, v in ((u0, v0), (u1, v1), (0.3 * u0 + 0.7 * u1, 0.8 * v0 + 0.2 * v1)):
            assert np.allclose(tuple(face.normalAt(u, v)), normal, atol=1e-9)
        outward = np.array(tuple(face.CenterOfMass - prism.CenterOfMass))
        assert float(outward @ normal) > 0
    assert plane_normal(_bump(App, Part)) is None


def test_a_part_is_offered_standing_on_its_planar_b_spline_sides(App, Part):
    """Read as curved, the side a part stands on counted as overhang (720 mm², the face
    itself), so the oblique prism was only offered on its ends: PrusaSlicer laid it on its
    side and printed it in 22 min, ours stood up took 25."""
    from freecad_conformal.geometry.face_normals import plane_normal
    from freecad_conformal.geometry.overhang import (base_area, orientation_candidates,
                                                     overhang_area)

    prism = samples.oblique_prism()
    candidates = orientation_candidates(prism)
    for face in (f for f in prism.Faces if type(f.Surface).__name__ == "BSplineSurface"):
        down = -plane_normal(face)
        assert any(float(down @ c) > 1.0 - 1e-9 for c in candidates)
        assert base_area(prism, down) == pytest.approx(face.Area, rel=1e-9)
        assert overhang_area(prism, down) < 1e-6


def _quadric_faces(App, Part):
    """Curved faces of every closed-form kind, in right- and left-handed frames, forward
    and reversed: a cylinder, cones widening and narrowing (and a face on a cone's far
    nappe, beyond its apex), a sphere, a ring torus."""
    cone = Part.makeCone(5.0, 2.0, 10.0).Faces[0].Surface
    apex = -cone.Radius / math.sin(cone.SemiAngle)
    shapes = [Part.makeCylinder(3.0, 5.0), Part.makeCone(5.0, 2.0, 10.0),
              cone.toShape(0.0, 2.0 * math.pi, apex + 1.0, apex + 5.0),
              Part.makeCone(2.0, 5.0, 10.0, App.Vector(1, 2, 3), App.Vector(1, 1, 0)),
              Part.makeSphere(4.0), Part.makeTorus(10.0, 2.0, App.Vector(0, 0, 0),
                                                   App.Vector(0, 1, 1))]
    mirrored = [s.mirror(App.Vector(0, 0, 0), App.Vector(1, 0, 0)) for s in shapes]
    faces = [f for s in shapes + mirrored for f in s.Faces if f.Surface.isPlanar() is False]
    return faces + [f.reversed() for f in faces]


def test_closed_form_normals_are_occs_on_quadrics_and_tori(App, Part):
    """Cylinders, cones, spheres and ring tori take their normals in closed form, with
    OCC's orientation (left-handed frames and reversed faces included): the same as
    Face.normalAt wherever OCC has a normal."""
    from freecad_conformal.geometry.face_normals import _closed_form, node_normals

    faces = _quadric_faces(App, Part)
    kinds = {type(f.Surface).__name__ for f in faces}
    assert kinds == {"Cylinder", "Cone", "Sphere", "Toroid"}
    for face in faces:
        u0, u1, v0, v1 = face.ParameterRange
        uv = [(u, v) for u in np.linspace(u0, u1, 7) for v in np.linspace(v0, v1, 7)]
        points = np.array([tuple(face.valueAt(u, v)) for u, v in uv])
        assert _closed_form(face, points) is not None
        found = node_normals(face, points, np.zeros((0, 3), dtype=int))
        for (u, v), normal in zip(uv, found):
            try:
                expected = np.array(tuple(face.normalAt(u, v)))
            except Exception:   # noqa: BLE001 - no normal at a pole or an apex
                continue
            np.testing.assert_allclose(normal, expected, atol=1e-9)


def test_a_spindle_torus_is_left_to_occ(App, Part):
    """Near its axis a point of a spindle torus lies on both sheets: no closed form."""
    from freecad_conformal.geometry.face_normals import _closed_form

    face = Part.makeTorus(2.0, 3.0).Faces[0]
    assert _closed_form(face, np.array([tuple(face.valueAt(0.3, 0.4))])) is None
