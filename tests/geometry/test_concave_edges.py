"""Inner angles of edges, measured inside the material from OCC normals."""
from __future__ import annotations

import math

import numpy as np
import pytest

from freecad_conformal.geometry import samples
from freecad_conformal.geometry.concave_edges import concave_edges, edge_angles, side_in_face


def test_box_edges_are_all_90_degrees_inside(Part):
    angles = edge_angles(Part.makeBox(10, 20, 30))
    assert len(angles) == 12
    assert all(math.degrees(a.inner_angle) == pytest.approx(90.0) for a in angles)
    assert concave_edges(Part.makeBox(10, 20, 30)) == []


def test_l_block_inner_edge_is_270_degrees_inside():
    block = samples.l_block()
    concave = concave_edges(block)
    assert len(concave) == 1
    assert math.degrees(concave[0].inner_angle) == pytest.approx(270.0)
    convex = [a for a in edge_angles(block) if not a.concave]
    assert convex and all(math.degrees(a.inner_angle) == pytest.approx(90.0) for a in convex)


def test_wedge_edge_angle_is_the_wedge_angle(Part, App):
    # A prism whose cross-section is a right triangle with a 30° corner.
    import math as m
    h = 10.0 * m.tan(m.radians(30))
    wire = Part.makePolygon([App.Vector(0, 0, 0), App.Vector(10, 0, 0), App.Vector(10, h, 0),
                             App.Vector(0, 0, 0)])
    prism = Part.Face(wire).extrude(App.Vector(0, 0, 5))
    inner = sorted(round(math.degrees(a.inner_angle), 6) for a in edge_angles(prism))
    assert inner.count(30.0) == 1 and inner.count(60.0) == 1
    assert inner.count(90.0) == 7


def test_cylinder_on_a_plate_meets_it_concavely_all_round(Part, App):
    plate = Part.makeBox(40, 40, 5)
    peg = Part.makeCylinder(5, 20, App.Vector(20, 20, 5))
    concave = concave_edges(plate.fuse(peg).removeSplitter())
    assert concave
    assert all(math.degrees(e.inner_angle) == pytest.approx(270.0, abs=0.5) for e in concave)


def _halves(solid, point, normal):
    from freecad_conformal.geometry.splitting_faces import plane_through, split_solid

    return split_solid(solid, [plane_through(np.asarray(point, float), np.asarray(normal, float),
                                             solid.BoundBox)])


def _indices(edges) -> list[int]:
    return sorted(e.edge_index for e in edges)


@pytest.mark.parametrize("name, point, normal", [
    # the L's concave edge lies in this plane: the cut flattens it on both pieces
    ("l_block", (0, 0, 30), (0, 0, 1)),
    ("l_block", (5, 0, 0), (1, 0, 0)),
    ("t_block", (0, 0, 20), (0, 0, 1)),
    ("hinge", (30, 0, 0), (1, 0, 0)),
    ("hinge", (0, 30, 0), (0, 1, 0)),
    ("hinge", (0, 0, 20), (0.3, 0.2, 0.93)),
])
def test_pieces_concave_edges_are_found_among_their_ancestors(name, point, normal):
    """Measuring only the edges on the uncut solid's concave edges finds every concave edge
    of a piece (the decomposition relies on it), including the cut that flattens one."""
    solid = samples.SAMPLES[name]()
    ancestor = concave_edges(solid)
    pieces = _halves(solid, point, normal)
    assert len(pieces) >= 2
    for piece in pieces:
        assert _indices(concave_edges(piece, within=ancestor)) == _indices(concave_edges(piece))
    if name == "l_block" and normal == (0, 0, 1):
        assert ancestor and all(concave_edges(p) == [] for p in pieces)


@pytest.mark.slow
def test_pieces_of_a_free_form_part_keep_their_concave_edges(parts_dir):
    from freecad_conformal.geometry.solids import load_shape

    arm = max(load_shape(parts_dir / "CrankArm.brep").Solids, key=lambda s: s.Volume)
    ancestor = concave_edges(arm)
    centre = np.array(tuple(arm.BoundBox.Center))
    found = 0
    for normal in ((1, 0, 0), (0, 1, 0), (0, 0, 1)):
        for piece in _halves(arm, centre, normal):
            own = concave_edges(piece)
            assert _indices(concave_edges(piece, within=ancestor)) == _indices(own)
            found += len(own)
    assert found > 0


@pytest.mark.parametrize("name", ["CrankArm.brep", "Pump_Nut.brep", "bottle.brep"])
def test_an_edges_orientation_tells_the_side_its_face_lies_on(parts_dir, name, App, Part):
    """`side_in_face` reads the side from the topology, on every edge of free-form and
    filleted parts, from both of its faces. The truth: of two points 0.01 mm either side of
    the edge, tangent to the face, the one on the face is nearer to it (CrankArm's arm has
    two B-spline faces so narrow at the edge that probes 2 µm either side both met them)."""
    import numpy as np

    from freecad_conformal.geometry.concave_edges import _normals_along, _vec
    from freecad_conformal.geometry.solids import load_shape

    read = 0
    for solid in load_shape(parts_dir / name).Solids:
        faces = list(solid.Faces)
        for angle in edge_angles(solid):
            edge = angle.edge
            first, last = edge.ParameterRange
            t = 0.5 * (first + last)
            point = _vec(edge.valueAt(t))
            tangent = _vec(edge.tangentAt(t))
            for index in angle.faces:
                face = faces[index]
                sign = side_in_face(edge, face)
                assert sign is not None
                normal = _normals_along(face, edge, [t], [edge.valueAt(t)])[0]
                # Read off the edge's curve on the face, as projecting the point reads it.
                u, v = face.Surface.parameter(edge.valueAt(t))
                assert np.linalg.norm(normal - _vec(face.normalAt(u, v))) < 1e-4, (name, angle.edge_index)
                side = np.cross(normal, tangent)
                side *= 1e-2 / np.linalg.norm(side)
                ahead, behind = (face.distToShape(Part.Vertex(App.Vector(*(point + s * side))))[0]
                                 for s in (1.0, -1.0))
                assert (ahead < behind) == (sign > 0), (name, angle.edge_index, ahead, behind)
                read += 1
    assert read > 100


def test_a_seam_leaves_the_side_to_probing(Part):
    cylinder = Part.makeCylinder(5.0, 10.0)
    face = next(f for f in cylinder.Faces if type(f.Surface).__name__ == "Cylinder")
    seam = next(e for e in face.Edges if e.isSeam(face))
    assert side_in_face(seam, face) is None


def test_a_solid_converted_from_a_mesh_pairs_every_edge_with_its_two_faces(App, Part):
    """A faceted solid (FreeCAD's shape from mesh, as users convert STL files): every edge
    has its two triangles, the pair each edge's neighbours give, and the notch's edges
    are concave. The faces were once found per edge by `ancestorsOfType`, which maps the
    whole solid at each call (70 s on 10,026 edges); the pass over faces must give the
    same pairs."""
    import Mesh

    notched = Part.makeBox(20, 10, 10).cut(Part.makeBox(8, 10, 5, App.Vector(6, 0, 5)))
    points, triangles = notched.tessellate(0.5)
    mesh = Mesh.Mesh([[points[i] for i in triangle] for triangle in triangles])
    shell = Part.Shape()
    shell.makeShapeFromMesh(mesh.Topology, 0.01)
    solid = Part.makeSolid(Part.makeShell(shell.Faces))
    angles = edge_angles(solid)
    assert len(angles) == len(solid.Edges)
    faces = solid.Faces
    for angle in angles:
        holding = [i for i, face in enumerate(faces)
                   if any(edge.isSame(angle.edge) for edge in face.Edges)]
        assert list(angle.faces) == holding
    concave = [a for a in angles if a.concave]
    # the notch's two inner corners (each split into triangle edges along its length)
    assert concave and all(abs(math.degrees(a.inner_angle) - 270.0) < 1e-6 for a in concave)
