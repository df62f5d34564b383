"""Faces' ends along a direction in closed form, against OCC's extrema."""
from __future__ import annotations

import math

import numpy as np
import pytest

from freecad_conformal.geometry.analytic_ends import edge_top, face_top
from freecad_conformal.geometry.overhang import CUBE_DIRECTIONS
from freecad_conformal.geometry.plane_curves import curve_name

#: How far (mm) a closed-form end may lie from OCC's: its extrema are iterative (2.3e-10 on
#: CrankArm's faces), the closed form is exact to rounding.
AGREE = 1e-9


def _directions(seed: int) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    return list(CUBE_DIRECTIONS) + [v / np.linalg.norm(v) for v in rng.normal(size=(14, 3))]


def _occ_top(App, Part, face, up: np.ndarray) -> float:
    """The face's highest point along `up` as OCC's extrema give it: a far plane's distance."""
    box = face.BoundBox
    centre = np.array([box.Center.x, box.Center.y, box.Center.z])
    reach = float(abs(centre @ up)) + 2 * box.DiagonalLength + 10.0
    u = np.cross(up, [0.0, 0.0, 1.0] if abs(up[2]) < 0.9 else [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    size = 4 * box.DiagonalLength + 10.0
    corner = centre + (reach - centre @ up) * up - 0.5 * size * (u + np.cross(up, u))
    far = Part.makePlane(size, size, App.Vector(*corner), App.Vector(*up), App.Vector(*u))
    return reach - far.distToShape(face)[0]


def _compare(App, Part, shape, directions) -> tuple[int, int, set[str]]:
    """(faces read in closed form, of them ending inside an edge, edge kinds met), each
    closed-form end checked against OCC's."""
    closed = inside = 0
    kinds: set[str] = set()
    for up in directions:
        for face in shape.Faces:
            top = face_top(face, up)
            if top is None:
                continue
            closed += 1
            kinds.update(curve_name(edge) for edge in face.Edges if not edge.Degenerated)
            assert top == pytest.approx(_occ_top(App, Part, face, up), abs=AGREE), (
                type(face.Surface).__name__, up)
            corners = np.array([tuple(v.Point) for v in face.Vertexes]) @ up
            inside += top > corners.max() + 1e-3
    return closed, inside, kinds


def test_every_conic_edges_end_matches_occ(App, Part):
    """Planes, cylinders and cones bounded by lines, circles, ellipses, hyperbolas and
    parabolas: a rod cut at a slant (ellipses), a cone cut along its axis (hyperbolas) and
    parallel to a ruling (a parabola). Most ends lie inside an edge, not at a vertex: a
    wrong critical parameter, or a parametrisation read the wrong way, misses them."""
    rod = Part.makeCylinder(4.0, 30.0, App.Vector(0, 0, 0), App.Vector(0.2, 0.1, 1.0))
    slant = Part.makeBox(40, 40, 40, App.Vector(-20, -20, 20))
    slant.rotate(App.Vector(0, 0, 20), App.Vector(1, 0.3, 0), 25.0)
    cone = Part.makeCone(10.0, 2.0, 20.0, App.Vector(30, 0, 0))
    along_axis = Part.makeBox(30, 30, 30, App.Vector(33, -15, -5))
    # A half-space whose plane, 7 mm in from the cone's base edge, runs parallel to the
    # ruling from (40, 0, 0) to (32, 0, 20).
    ruling = Part.makeBox(100, 100, 100, App.Vector(-50, -50, 0))
    ruling.rotate(App.Vector(0, 0, 0), App.Vector(0, 1, 0), math.degrees(math.atan2(20.0, 8.0)))
    ruling.translate(App.Vector(23, 0, 0))
    part = Part.makeCompound([rod.cut(slant), cone.cut(along_axis), cone.common(ruling)])
    closed, inside, kinds = _compare(App, Part, part, _directions(3))
    assert {"Ellipse", "Hyperbola", "Parabola", "Circle"} <= kinds, kinds
    assert closed > 100 and inside > 20, (closed, inside)


def test_pump_nut_faces_end_where_occ_says(App, Part, parts_dir):
    """The nut's chamfer cones meet its flats in hyperbolas: every plane and cone face's
    end along 40 directions is OCC's; its fillet tori are left to OCC."""
    from freecad_conformal.geometry.solids import load_shape

    nut = load_shape(parts_dir / "Pump_Nut.brep")
    closed, inside, kinds = _compare(App, Part, nut, _directions(7))
    assert closed > 500 and inside > 50 and "Hyperbola" in kinds
    tori = [face for face in nut.Faces if type(face.Surface).__name__ == "Toroid"]
    assert tori and all(face_top(face, np.array([0.0, 0.0, 1.0])) is None for face in tori)


def test_faces_without_a_closed_form_are_left_to_occ(App, Part):
    """A sphere's or a torus' top can lie inside the face, a B-spline edge has no closed
    form: None, so the caller measures them."""
    up = np.array([0.0, 0.0, 1.0])
    assert face_top(Part.makeSphere(5.0).Faces[0], up) is None
    assert face_top(Part.makeTorus(10.0, 2.0).Faces[0], up) is None
    points = [App.Vector(0, 0, 0), App.Vector(5, 3, 0), App.Vector(10, -2, 0), App.Vector(15, 0, 0)]
    spline = Part.BSplineCurve()
    spline.interpolate(points)
    wall = spline.toShape().extrude(App.Vector(0, 0, 5))
    assert edge_top(spline.toShape(), np.array([0.0, 1.0, 0.0])) is None
    assert face_top(wall.Faces[0], up) is None
