"""Surfaces of revolution of circles read as tori: a plane meets them in closed form."""
from __future__ import annotations

import math

import numpy as np
import pytest

from freecad_conformal.geometry.face_sections import FaceCutter
from freecad_conformal.geometry.loops import dense_area
from freecad_conformal.geometry.revolved_torus import RevolvedTorus, revolved_torus
from tests.geometry.test_face_cut import _compare

#: (u, v) samples per direction of a face's box when checking the torus against the surface.
GRID = 7


def _revolved(App, Part, kind: str):
    """Solids with surfaces of revolution of circles: profiles swept along a quarter arc
    (FreeCAD's sweep makes the bend so; its revolve makes tori on FreeCAD 1.0)."""
    V = App.Vector
    path = Part.Wire(Part.Circle(V(40, 0, 0), V(0, 1, 0), 40).toShape(math.pi / 2, math.pi))

    def swept(*edges):
        return path.makePipeShell([Part.Wire(list(edges))], True, False)

    def circle(radius: float, normal=(0, 0, 1)):
        return Part.Circle(V(0, 0, 0), V(*normal), radius)
    if kind == "elbow":
        return swept(circle(10).toShape()).cut(swept(circle(7).toShape()))
    if kind == "reversed":
        # The profile's circle runs the other way: the torus' v runs against its parameter.
        return swept(circle(6, (0, 0, -1)).toShape())
    # A half disc (D profile), turned about a leaning axis: faces trimmed in v as well as
    # in u, the surfaces placed by the shape's location.
    arc = Part.ArcOfCircle(circle(6), 0.3, 0.3 + math.pi)
    solid = swept(arc.toShape(), Part.LineSegment(arc.EndPoint, arc.StartPoint).toShape())
    solid.rotate(V(3, 2, 1), V(1, 2, 0.5), 33)
    return solid


KINDS = ("elbow", "reversed", "half_disc")


def _revolution_faces(solid) -> list:
    faces = [f for f in solid.Faces if type(f.Surface).__name__ == "SurfaceOfRevolution"]
    assert faces, "the solid has no surface of revolution to test"
    return faces


@pytest.mark.parametrize("kind", KINDS)
def test_each_point_of_the_surface_is_the_torus_point_of_the_mapped_parameters(App, Part, kind):
    """The torus' v of the surface's point at (u, v) is v_offset + v_sign·v, and the point is
    on the torus: a wrong offset or sense would cut the faces' curves in the wrong place."""
    for face in _revolution_faces(_revolved(App, Part, kind)):
        surface = face.Surface
        torus = revolved_torus(surface)
        assert isinstance(torus, RevolvedTorus)
        centre, w = np.asarray(torus.Center), np.asarray(torus.Axis)
        u0, u1, v0, v1 = face.ParameterRange
        for u in np.linspace(u0, u1, GRID):
            for v in np.linspace(v0, v1, GRID):
                rel = np.array(tuple(surface.value(float(u), float(v)))) - centre
                along = float(rel @ w)
                radial = float(np.linalg.norm(rel - along * w))
                torus_v = math.atan2(along, radial - torus.MajorRadius)
                assert math.hypot(radial - torus.MajorRadius, along) == pytest.approx(
                    torus.MinorRadius, abs=1e-9)
                turn = (torus_v - (torus.v_offset + torus.v_sign * v)) % (2 * math.pi)
                assert min(turn, 2 * math.pi - turn) < 1e-9


def test_the_solids_run_the_circle_both_ways(App, Part):
    """The parameter check above meets both senses of the circle (else a sense error in
    one of them would pass unseen)."""
    signs = {revolved_torus(face.Surface).v_sign for kind in KINDS
             for face in _revolution_faces(_revolved(App, Part, kind))}
    assert signs == {1.0, -1.0}


def test_other_revolutions_are_left_to_occ(App, Part):
    """A circle whose plane misses the axis, a spindle (radius over the distance to the
    axis) and a revolved line are no ring tori."""
    V = App.Vector
    leaning = Part.Circle(V(20, 0, 0), V(0, 1, 0.1), 5)
    spindle = Part.Circle(V(4, 0, 0), V(0, 1, 0), 5)
    line = Part.LineSegment(V(20, 0, 0), V(25, 0, 5))
    for curve in (leaning, spindle, line):
        assert revolved_torus(Part.SurfaceOfRevolution(curve, V(0, 0, 0), V(0, 0, 1))) is None


@pytest.mark.slow
@pytest.mark.parametrize("kind", KINDS)
def test_revolved_circle_sections_match_the_boolean(App, Part, kind):
    """Every layer cut face by face, through the closed form, with the Boolean's faces and
    area (a dense polygon of its wires: OCC's own area of walked curves errs more)."""
    solid = _revolved(App, Part, kind)
    for direction in ((1, 0.2, 0.1), (0.3, -0.5, 0.8)):
        n = np.asarray(direction, dtype=float) / np.linalg.norm(direction)
        cutter = FaceCutter(solid.Solids[0], n)
        assert all(isinstance(data.cut_surface, RevolvedTorus) for data in cutter.faces
                   if type(data.face.Surface).__name__ == "SurfaceOfRevolution")
        rows = _compare(solid, direction, spacing=0.9)
        done = [(fast, reference) for _, fast, reference in rows if fast is not None]
        assert len(done) == len(rows)
        for mine, reference in done:
            assert mine.area == pytest.approx(dense_area(reference.faces, reference.frame),
                                              rel=5e-6, abs=1e-9)
            assert len(mine.faces) == len(reference.faces)
