"""Shape methods and properties read through their type (geometry/shape_access.py), and
vertex points read once per shape (geometry/shape_parts.py): the same values as the
attributes, never another shape's."""
from __future__ import annotations

import numpy as np

from freecad_conformal.geometry import samples
from freecad_conformal.geometry.shape_access import hash_code, is_same, orientation, point
from freecad_conformal.geometry.shape_cache import ShapeCache
from freecad_conformal.geometry.shape_parts import faces, heights, vertex_points


def test_type_level_reads_equal_the_attributes(App):
    solid = samples.hinge()
    faces = solid.Faces
    reversed_face = faces[0].reversed()
    moved = faces[0].translated(App.Vector(5, 0, 0))
    for a in (faces[0], faces[1], reversed_face, moved, solid):
        assert hash_code(a) == a.hashCode()
        assert orientation(a) == a.Orientation
        for b in (faces[0], faces[1], reversed_face, moved):
            assert is_same(a, b) == a.isSame(b)
    assert orientation(reversed_face) != orientation(faces[0])
    for vertex in solid.Vertexes:
        assert point(vertex) == tuple(vertex.Point)


def test_an_oriented_cache_tells_a_reversed_face_apart():
    face = samples.hinge().Faces[0]
    cache: ShapeCache[str] = ShapeCache(limit=10, oriented=True)
    assert cache.get((face,), lambda: "forward") == "forward"
    assert cache.get((face.reversed(),), lambda: "reversed") == "reversed"
    assert cache.get((face,), lambda: "again") == "forward"


def test_vertex_points_are_read_once_and_follow_the_location(App):
    solid = samples.jack()
    points = vertex_points(solid)
    assert points is vertex_points(solid)           # read once per shape
    assert [tuple(p) for p in points] == [tuple(v.Point) for v in solid.Vertexes]
    moved = solid.translated(App.Vector(0, 0, 7))
    assert [tuple(p) for p in vertex_points(moved)] == [tuple(v.Point) for v in moved.Vertexes]
    assert vertex_points(moved)[0][2] == points[0][2] + 7


def test_heights_are_the_products_the_vertices_gave_before():
    solid = samples.jack()
    direction = np.array([0.3, -0.4, 0.866])
    direction /= np.linalg.norm(direction)
    expected = [float(np.array(tuple(v.Point)) @ direction) for v in solid.Vertexes]
    assert heights(solid, direction) == expected     # bit for bit: plans read these


def test_faces_are_read_once_per_shape_and_orientation(App):
    solid = samples.hinge()
    listed = faces(solid)
    assert listed is faces(solid)
    assert all(a.isSame(b) and a.Orientation == b.Orientation
               for a, b in zip(listed, solid.Faces)) and len(listed) == len(solid.Faces)
    # A reversed solid's faces are reversed: not the cached ones.
    turned = solid.reversed()
    assert [f.Orientation for f in faces(turned)] == [f.Orientation for f in turned.Faces]
    assert faces(turned)[0].Orientation != listed[0].Orientation
    moved = solid.translated(App.Vector(3, 0, 0))
    assert faces(moved)[0].BoundBox.XMin == moved.Faces[0].BoundBox.XMin
