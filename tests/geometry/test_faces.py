"""Face analysis on analytic faces and on the real parts (bottle, revolved sphere)."""
from __future__ import annotations

import math
from collections import Counter

import numpy as np
import pytest

from freecad_conformal.errors import GeometryError
from freecad_conformal.geometry.faces import (
    classify_face, classify_faces, curvature_at_point, domain_grid, face_by_name, face_kind,
    normals_at, points_at, principal_curvatures, smallest_radius)


def _lateral(shape, kind):
    return next(f for f in shape.Faces if face_kind(f) == kind)


def _occ_sorted(face, u, v):
    """OCC's own principal curvatures in this module's sign convention, k1 >= k2."""
    values = sorted((-k for k in face.curvatureAt(u, v)), reverse=True)
    return values


def test_kinds_of_primitive_faces(Part):
    assert face_kind(Part.makeBox(1, 2, 3).Faces[0]) == "plane"
    assert face_kind(_lateral(Part.makeCylinder(2, 5), "cylinder")) == "cylinder"
    assert face_kind(Part.makeSphere(3).Faces[0]) == "sphere"
    assert face_kind(_lateral(Part.makeCone(1, 3, 4), "cone")) == "cone"
    assert face_kind(Part.makeTorus(10, 2).Faces[0]) == "torus"
    spline = Part.makeSphere(3).Faces[0].toNurbs().Faces[0]
    assert face_kind(spline) == "bspline"


def test_cylinder_curvature_and_directions(Part):
    face = _lateral(Part.makeCylinder(4, 10), "cylinder")
    c = principal_curvatures(face, 0.7, 3.0)
    assert c.k1 == pytest.approx(0.25, abs=1e-12)
    assert c.k2 == pytest.approx(0.0, abs=1e-12)
    # the curved direction runs round the axis, the straight one along it
    assert abs(c.d1 @ np.array([0, 0, 1])) < 1e-12
    assert abs(abs(c.d2 @ np.array([0, 0, 1])) - 1) < 1e-12
    expected_normal = np.array([math.cos(0.7), math.sin(0.7), 0.0])
    np.testing.assert_allclose(c.normal, expected_normal, atol=1e-12)
    assert c.radii[0] == pytest.approx(4.0) and math.isinf(c.radii[1])
    assert smallest_radius(face) == pytest.approx(4.0)


def test_bore_is_concave(App, Part):
    block = Part.makeBox(10, 10, 10).cut(Part.makeCylinder(3, 10, App.Vector(5, 5, 0)))
    bore = _lateral(block, "cylinder")
    u0, _, _, _ = bore.ParameterRange
    c = principal_curvatures(bore, u0 + 0.3, 4.0)
    assert c.k2 == pytest.approx(-1 / 3, abs=1e-12) and c.k1 == pytest.approx(0, abs=1e-12)
    # the normal points out of the material: towards the bore axis
    radial = c.point[:2] - np.array([5.0, 5.0])
    assert c.normal[:2] @ radial < 0


def test_sphere_umbilic_everywhere(Part):
    face = Part.makeSphere(5).Faces[0]
    for u, v in ((0.1, 0.2), (2.0, -1.0), (4.0, 1.2)):
        c = principal_curvatures(face, u, v)
        assert c.k1 == pytest.approx(0.2, abs=1e-12) and c.k2 == pytest.approx(0.2, abs=1e-12)
        assert abs(c.d1 @ c.d2) < 1e-12 and abs(c.d1 @ c.normal) < 1e-12
        np.testing.assert_allclose(c.normal, c.point / 5.0, atol=1e-12)


def test_torus_against_closed_form_and_occ(Part):
    major, minor = 10.0, 2.0
    face = Part.makeTorus(major, minor).Faces[0]
    outer = principal_curvatures(face, 0.4, 0.0)          # outer equator
    assert outer.k1 == pytest.approx(1 / minor) and outer.k2 == pytest.approx(1 / (major + minor))
    inner = principal_curvatures(face, 0.4, math.pi)      # inner equator: saddle
    assert inner.k1 == pytest.approx(1 / minor)
    assert inner.k2 == pytest.approx(-1 / (major - minor))
    for u, v in ((0.3, 0.9), (2.2, 2.5), (5.0, 4.4)):
        c = principal_curvatures(face, u, v)
        assert [c.k1, c.k2] == pytest.approx(_occ_sorted(face, u, v), abs=1e-12)
    assert smallest_radius(face) == pytest.approx(minor)
    fat = Part.makeTorus(3.0, 2.5).Faces[0]               # meridian radius R − r = 0.5 < r
    assert smallest_radius(fat) == pytest.approx(0.5, rel=1e-6)


def test_cone_smallest_radius_is_smallest_circle(Part):
    face = _lateral(Part.makeCone(2, 5, 10), "cone")
    alpha = math.atan(3 / 10)
    assert smallest_radius(face) == pytest.approx(2 / math.cos(alpha), rel=1e-12)
    info = classify_face(face, "Face1")
    assert info.semi_angle == pytest.approx(alpha)
    u0, u1, v0, _ = face.ParameterRange
    assert principal_curvatures(face, 0.5 * (u0 + u1), v0).smallest_radius == pytest.approx(
        smallest_radius(face), rel=1e-12)


def test_bspline_matches_occ_and_search(Part):
    face = Part.makeSphere(3).Faces[0].toNurbs().Faces[0]
    grid = domain_grid(face, 6)
    for u, v in grid:
        c = principal_curvatures(face, u, v)
        assert [c.k1, c.k2] == pytest.approx(_occ_sorted(face, u, v), abs=1e-9)
    # a NURBS sphere is still a sphere: the search finds r = 3 (within the fit's accuracy)
    assert smallest_radius(face) == pytest.approx(3.0, rel=1e-7)


def test_normal_field_and_point_lookup(Part):
    face = Part.makeSphere(5).Faces[0]
    uv = np.array([[0.2, 0.1], [1.5, -0.7], [3.3, 1.1]])
    np.testing.assert_allclose(normals_at(face, uv), points_at(face, uv) / 5.0, atol=1e-12)
    c = curvature_at_point(face, [0.0, 7.0, 1.0])
    np.testing.assert_allclose(c.point, np.array([0, 7, 1]) / math.sqrt(50) * 5, atol=1e-9)


def test_face_by_name_errors(Part):
    box = Part.makeBox(1, 1, 1)
    assert face_by_name(box, "Face6").isSame(box.Faces[5])
    with pytest.raises(GeometryError, match="Face7 is not in the part: it has 6 faces"):
        face_by_name(box, "Face7")
    with pytest.raises(GeometryError, match="not of the form FaceN"):
        face_by_name(box, "Edge1")


@pytest.mark.parts
def test_revolved_sphere_part(parts_dir, Part):
    shape = Part.read(str(parts_dir / "revolved_sphere.step"))
    infos = classify_faces(shape)
    assert [i.kind for i in infos] == ["sphere"]
    assert infos[0].radius == pytest.approx(5.0) and infos[0].smallest_radius == pytest.approx(5.0)
    face = shape.Faces[0]
    for u, v in domain_grid(face, 5):
        c = principal_curvatures(face, u, v)
        assert c.k1 == pytest.approx(0.2, abs=1e-9) and c.k2 == pytest.approx(0.2, abs=1e-9)
        np.testing.assert_allclose(c.normal, (c.point - infos[0].center) / 5.0, atol=1e-9)


@pytest.mark.parts
def test_bottle_faces(parts_dir, Part):
    shape = Part.read(str(parts_dir / "bottle.brep"))
    infos = classify_faces(shape)
    kinds = Counter(i.kind for i in infos)
    assert set(kinds) == {"bspline", "cylinder", "plane", "sphere", "torus"}
    assert len(infos) == 71
    assert sum(i.area for i in infos) == pytest.approx(23266.0124, rel=1e-6)
    for info, face in zip(infos, shape.Faces):
        if info.kind == "plane":
            assert math.isinf(info.smallest_radius)
        if info.kind in ("cylinder", "sphere"):
            assert info.smallest_radius == pytest.approx(face.Surface.Radius)
        if info.kind == "torus":
            assert info.smallest_radius <= face.Surface.MinorRadius + 1e-12
    # the thread faces (B-spline): exact curvature agrees with OCC at every grid point
    for info, face in zip(infos, shape.Faces):
        if info.kind != "bspline":
            continue
        for u, v in domain_grid(face, 5):
            c = principal_curvatures(face, u, v)
            assert [c.k1, c.k2] == pytest.approx(_occ_sorted(face, u, v), rel=1e-9, abs=1e-12)
            assert c.smallest_radius >= info.smallest_radius - 1e-9
