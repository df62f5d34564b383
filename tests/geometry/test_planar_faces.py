"""Section faces from closed wires: loops oriented, ordered and nested from their polygons
only where the polygon's error cannot change the answer (geometry/planar_faces.py)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from freecad_conformal.geometry import planar_faces
from freecad_conformal.geometry.planar_faces import LOOP_DEFLECTION, _faces_of_wires


@pytest.fixture
def plane(App, Part):
    return Part.Plane(App.Vector(0, 0, 0), App.Vector(0, 0, 1))


def _polyline(App, Part, points):
    vectors = [App.Vector(x, y, 0) for x, y in points]
    return Part.Wire([Part.LineSegment(a, b).toShape()
                      for a, b in zip(vectors, vectors[1:] + vectors[:1])])


def _circle(App, Part, centre, radius):
    return Part.Wire([Part.makeCircle(radius, App.Vector(*centre, 0))])


def test_loops_come_in_the_order_of_their_exact_areas(App, Part, plane):
    """A circle's polygon falls short of its area by more than the 0.05 mm² a square is
    smaller: ordered by the polygons the square would come first. Equal circles keep the
    order they were given in (as a stable sort on exact areas keeps them)."""
    radius = 5.0
    side = math.sqrt(math.pi * radius ** 2 - 0.05)
    wires = [_polyline(App, Part, [(20, 0), (20 + side, 0), (20 + side, side), (20, side)]),
             _circle(App, Part, (0, 0), radius),
             _circle(App, Part, (0, 40), 3.0),
             _circle(App, Part, (40, 40), 3.0),
             _circle(App, Part, (0, -40), 7.0)]
    frame = planar_faces.PlaneFrame(plane)
    loops = [planar_faces._Loop(wire, plane, frame) for wire in wires]
    assert abs(loops[1].polygon_area) < abs(loops[0].polygon_area)  # the trap is set
    ordered = planar_faces._largest_first(loops)
    exact = sorted(range(len(wires)), key=lambda i: -abs(Part.Face(plane, [wires[i]]).Area))
    assert [loops.index(loop) for loop in ordered] == exact == [4, 1, 0, 2, 3]


def test_a_hole_beyond_its_outer_loops_polygon_is_still_a_hole(App, Part, plane):
    """A small hole whose probe point lies between a chord of the circle's polygon and the
    circle: the polygon says outside, OCC inside. One face with the hole must come out,
    not two islands."""
    circle = _circle(App, Part, (0, 0), 5.0)
    polygon = np.array([(p.x, p.y) for p in circle.discretize(Deflection=LOOP_DEFLECTION)])
    a, b = polygon[10], polygon[11]
    middle = 0.5 * (a + b)
    sagitta = 5.0 - float(np.linalg.norm(middle))
    assert sagitta > 1e-3
    out = middle / np.linalg.norm(middle)
    along = np.array([-out[1], out[0]])
    probe = (5.0 - 0.5 * sagitta) * out
    corners = [probe - 1e-3 * along, probe + 1e-3 * along,
               probe + 1e-3 * along - 0.05 * out, probe - 1e-3 * along - 0.05 * out]
    hole = _polyline(App, Part, corners)
    assert not planar_faces._inside_polygon(probe, polygon)
    faces = _faces_of_wires([hole, circle], plane)
    assert faces is not None and len(faces) == 1
    assert len(faces[0].face.Wires) == 2
    assert faces[0].area == pytest.approx(math.pi * 25.0 - 2e-3 * 0.05, rel=1e-12)


def test_clockwise_and_nested_loops_make_faces_with_their_holes(App, Part, plane):
    """Wires in any orientation: a square turning clockwise with a round hole holding an
    island, and a thin sliver whose polygon cannot tell its sign (the exact area does)."""
    outer = _polyline(App, Part, [(0, 0), (0, 20), (20, 20), (20, 0)])       # clockwise
    hole = _circle(App, Part, (10, 10), 6.0)
    island = _polyline(App, Part, [(8, 8), (12, 8), (12, 12), (8, 12)])
    sliver = _polyline(App, Part, [(30, 0), (30, 1e-3), (60, 1e-3), (60, 0)])  # clockwise
    faces = _faces_of_wires([island, sliver, outer, hole], plane)
    assert faces is not None
    areas = sorted(item.area for item in faces)
    assert areas == pytest.approx(sorted([400 - math.pi * 36, 16.0, 0.03]), rel=1e-9)
    assert all(item.face.Area > 0 for item in faces)
    assert sorted(len(item.face.Wires) for item in faces) == [1, 1, 2]


def test_a_sliver_loop_is_left_to_the_boolean(App, Part, plane):
    flat = _polyline(App, Part, [(0, 0), (10, 0), (10, 1e-11), (0, 1e-11)])
    assert _faces_of_wires([flat], plane) is None


def test_section_areas_are_integrated_only_when_read(App, Part):
    """Layers read loops, not moments: a section's faces are not integrated until its
    area or centroid is read, and then they are OCC's exact values."""
    from freecad_conformal.geometry.sections import PlanarSlicer

    cylinder = Part.makeCylinder(5.0, 10.0)
    section = PlanarSlicer(cylinder, (1, 0, 0)).sections([1.0])[0]
    assert section._measures is None
    assert section.polygons().area == pytest.approx(2 * math.sqrt(24) * 10.0, rel=1e-3)
    assert section._measures is None
    assert section.area == pytest.approx(2 * math.sqrt(25 - 1) * 10.0, rel=1e-12)
    assert section.centroid == pytest.approx([1.0, 0.0, 5.0], abs=1e-9)


def test_loops_of_faces_built_here_need_no_outer_wire_classification(App, Part):
    """Faces built here list their outer wire first: their loops come out as OCC's
    classification of the wires makes them, without asking it (0.7 ms a face)."""
    from freecad_conformal.geometry import loops as loops_module
    from freecad_conformal.geometry.sections import PlanarSlicer

    tube = Part.makeCylinder(10, 20).cut(Part.makeCylinder(6, 20))
    tube = tube.cut(Part.makeBox(2, 2, 20, App.Vector(-1, -8.9, 0)))    # a hole in its wall
    section = PlanarSlicer(tube, (0.3, 0.1, 1.0)).sections([8.0])[0]
    assert section._outer_first == [True] and len(section.faces[0].Wires) == 3
    classified = loops_module.loops_of_faces(section.faces, section.frame,
                                             section.chord_tolerance)

    class Unclassified:
        """A face that fails the test when asked for its outer wire."""

        def __init__(self, face):
            self._face = face

        def __getattr__(self, name):
            if name == "OuterWire":
                pytest.fail("OuterWire asked")
            return getattr(self._face, name)

    told = loops_module.loops_of_faces([Unclassified(f) for f in section.faces], section.frame,
                                       section.chord_tolerance, outer_first=section._outer_first)
    assert [loop.outer for loop in told] == [loop.outer for loop in classified] == \
        [True, False, False]
    assert all(np.array_equal(a.points, b.points) for a, b in zip(told, classified))
    assert section.polygons().equals_exact(
        loops_module.polygons_of_loops(classified), 0.0)


def test_points_array_reads_vectors_in_order(App):
    from freecad_conformal.geometry.frames import points_array

    vectors = [App.Vector(1.5, -2.0, 1e-17), App.Vector(3, 4, 5)]
    assert np.array_equal(points_array(vectors), [[1.5, -2.0, 1e-17], [3, 4, 5]])
    assert points_array(iter(vectors)).shape == (2, 3)
    assert points_array([]).shape == (0, 3)
