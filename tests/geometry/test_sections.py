"""Exact planar sections against closed forms, at awkward places, and on the real parts."""
from __future__ import annotations

import math
import time

import numpy as np
import pytest

from freecad_conformal.errors import GeometryError
from freecad_conformal.geometry.sections import PlanarSlicer, planar_sections, uniform_heights

#: The accuracy the issue asks of exact sections against closed forms.
REL = 1e-9


def rel_err(value: float, expected: float) -> float:
    return abs(value - expected) / abs(expected)


def test_box_section_area_and_centroid(App, Part):
    box = Part.makeBox(20, 10, 5, App.Vector(1, 2, 3))
    section = PlanarSlicer(box).section(4.0)
    assert rel_err(section.area, 200.0) < REL
    assert np.allclose(section.centroid, [11, 7, 4], atol=1e-9)
    assert [loop.outer for loop in section.loops] == [True]
    assert section.loops[0].polygon_area == pytest.approx(200.0, rel=1e-12)


@pytest.mark.parametrize("height", [0.0, 2.5, -4.9, 4.99])
def test_sphere_section_is_disk(Part, height):
    section = PlanarSlicer(Part.makeSphere(5)).section(height)
    assert rel_err(section.area, math.pi * (25 - height ** 2)) < REL
    assert np.allclose(section.centroid, [0, 0, height], atol=1e-9)


def test_cylinder_oblique_section_is_ellipse(App, Part):
    cylinder = Part.makeCylinder(5, 100, App.Vector(0, 0, -50))
    tilt = math.radians(30)
    direction = (math.sin(tilt), 0.0, math.cos(tilt))
    section = PlanarSlicer(cylinder, direction).section(0.0)
    assert rel_err(section.area, math.pi * 25 / math.cos(tilt)) < REL
    assert np.allclose(section.centroid, 0, atol=1e-9)
    polygon = section.polygons()
    # The polygon is within the chord tolerance of the exact ellipse: area off by < 1e-3 relative.
    assert polygon.area == pytest.approx(section.area, rel=1e-3)


def test_cone_section(Part):
    cone = Part.makeCone(5, 2, 10)
    radius = 5 - 3 * 0.4
    section = PlanarSlicer(cone).section(4.0)
    assert rel_err(section.area, math.pi * radius ** 2) < REL
    assert np.allclose(section.centroid, [0, 0, 4], atol=1e-9)


def test_torus_sections_have_holes_and_islands(Part):
    torus = Part.makeTorus(10, 2)
    across = PlanarSlicer(torus).section(1.0)        # an annulus: one island with a hole
    s = math.sqrt(4 - 1)
    assert rel_err(across.area, 4 * math.pi * 10 * s) < REL
    assert sorted(loop.outer for loop in across.loops) == [False, True]
    assert len(across.polygons().geoms) == 1 and len(across.polygons().geoms[0].interiors) == 1
    through_axis = PlanarSlicer(torus, (1, 0, 0)).section(0.0)  # two disks: two islands
    assert rel_err(through_axis.area, 2 * math.pi * 4) < REL
    assert [loop.outer for loop in through_axis.loops] == [True, True]
    assert np.allclose(through_axis.centroid, 0, atol=1e-9)
    hole = [loop for loop in across.loops if not loop.outer][0]
    assert rel_err(hole.area, math.pi * (10 - s) ** 2) < REL


def test_loop_orientation_outer_ccw_holes_cw(App, Part):
    plate = Part.makeBox(30, 30, 4).cut(Part.makeCylinder(5, 4, App.Vector(15, 15, 0)))
    section = PlanarSlicer(plate).section(2.0)
    for loop in section.loops:
        signed = 0.5 * np.sum(loop.points[:, 0] * np.roll(loop.points[:, 1], -1)
                              - loop.points[:, 1] * np.roll(loop.points[:, 0], -1))
        assert (signed > 0) == loop.outer
    assert rel_err(section.area, 900 - 25 * math.pi) < REL


def test_plane_on_a_horizontal_face_returns_the_closed_section(App, Part):
    l_block = Part.makeBox(20, 10, 10).fuse(Part.makeBox(10, 10, 20)).removeSplitter()
    slicer = PlanarSlicer(l_block)
    on_step = slicer.section(10.0)
    assert rel_err(on_step.area, 200.0) < REL
    assert len(on_step.loops) == 1, "the step face and the column's section form one island"
    assert rel_err(slicer.section(10.0 + 1e-6).area, 100.0) < REL
    assert rel_err(slicer.section(0.0).area, 200.0) < REL   # the bottom face itself


def test_plane_through_edge_vertex_and_tangencies_is_empty_or_exact(App, Part):
    cube = Part.makeBox(10, 10, 10)
    cube.rotate(App.Vector(0, 0, 0), App.Vector(1, 0, 0), 45)     # an edge on top
    slicer = PlanarSlicer(cube)
    assert slicer.section(cube.BoundBox.ZMax).is_empty
    assert rel_err(slicer.section(10 / math.sqrt(2)).area, 10 * 10 * math.sqrt(2)) < REL
    corner = Part.makeBox(10, 10, 10)
    corner.rotate(App.Vector(0, 0, 0), App.Vector(1, 0, 0), 45)
    corner.rotate(App.Vector(0, 0, 0), App.Vector(0, 1, 0), math.degrees(math.atan(1 / math.sqrt(2))))
    top = PlanarSlicer(corner).section(corner.BoundBox.ZMax)       # through a vertex only
    assert top.is_empty and top.area == 0.0 and np.all(np.isnan(top.centroid))
    lying = Part.makeCylinder(5, 20, App.Vector(0, 0, 0), App.Vector(1, 0, 0))
    slicer = PlanarSlicer(lying)
    assert slicer.section(5.0).is_empty                              # tangent on top
    near = slicer.section(5.0 - 1e-4)                                # a thin strip below it
    assert rel_err(near.area, 20 * 2 * math.sqrt(25 - (5 - 1e-4) ** 2)) < 1e-6
    assert PlanarSlicer(Part.makeSphere(5)).section(5.0).is_empty   # tangent sphere
    assert PlanarSlicer(Part.makeSphere(5)).section(50.0).loops == []  # beyond the part


def test_compound_of_two_solids_is_cut_per_solid(App, Part):
    pair = Part.Compound([Part.makeBox(10, 10, 10),
                              Part.makeSphere(3, App.Vector(30, 0, 5))])
    section = PlanarSlicer(pair).section(5.0)
    assert rel_err(section.area, 100 + 9 * math.pi) < REL
    assert len([loop for loop in section.loops if loop.outer]) == 2
    expected = (np.array([5, 5, 5]) * 100 + np.array([30, 0, 5]) * 9 * math.pi) / (100 + 9 * math.pi)
    assert np.allclose(section.centroid, expected, atol=1e-9)


def test_explicit_heights_and_order_are_kept(Part):
    stack = planar_sections(Part.makeSphere(5), heights=[3.0, -1.0, 0.0, 3.0])
    assert [layer.height for layer in stack.layers] == [3.0, -1.0, 0.0, 3.0]
    assert [round(layer.area, 9) for layer in stack.layers] == [
        round(math.pi * 16, 9), round(math.pi * 24, 9), round(math.pi * 25, 9), round(math.pi * 16, 9)]


def test_uniform_heights_are_mid_layer(App, Part):
    heights = uniform_heights(Part.makeBox(1, 1, 1, App.Vector(0, 0, 2)), (0, 0, 1), 0.25)
    assert heights == pytest.approx([2.125, 2.375, 2.625, 2.875])


@pytest.mark.slow
@pytest.mark.parametrize("method", ["fork", "forkserver"])
def test_parallel_sections_equal_serial(Part, monkeypatch, method):
    """Both ways of starting workers: fork (OCCT < 7.8) and a fork server whose workers build
    the slicer from BREP text (OCCT 7.8's Boolean thread pool does not survive fork)."""
    from freecad_conformal.geometry import section_pool

    if method == "fork" and section_pool.occ_version() >= section_pool.THREAD_POOL_OCC:
        pytest.skip("OCCT >= 7.8: forked workers may deadlock on its thread pool")
    monkeypatch.setattr(section_pool, "start_method", lambda: method)
    torus = Part.makeTorus(10, 2)
    serial = planar_sections(torus, (0.3, 0.2, 1.0), layer=0.1)
    parallel = planar_sections(torus, (0.3, 0.2, 1.0), layer=0.1, workers=2)
    assert len(serial.layers) == len(parallel.layers) > 32
    for a, b in zip(serial.layers, parallel.layers):
        assert a.height == b.height
        assert a.area == pytest.approx(b.area, rel=1e-12, abs=1e-12)


def test_parallel_sections_share_the_work_and_the_boolean_fallbacks(App, Part):
    """Steps every 1 mm put the solids' vertices on some planes: those layers take the
    Boolean (one job per solid, so a worker takes one), and each layer is reported once."""
    pyramid = Part.makeBox(20, 20, 1)
    for k in range(1, 8):
        pyramid = pyramid.fuse(Part.makeBox(20 - 2 * k, 20 - 2 * k, 1, App.Vector(k, k, k)))
    pyramid = pyramid.removeSplitter()
    other = pyramid.copy()
    other.translate(App.Vector(30, 0, 0))
    steps = Part.Compound([pyramid, other])
    heights = [0.05 + 0.1 * k for k in range(80)]  # 1.05, 2.05, ...: generic; 1.0 ... below
    heights += [float(k) for k in range(1, 8)]
    serial_slicer = PlanarSlicer(steps, (0, 0, 1))
    serial = serial_slicer.sections(heights)
    seen = []
    parallel_slicer = PlanarSlicer(steps, (0, 0, 1))
    parallel = parallel_slicer.sections(heights, lambda d, t: seen.append((d, t)), workers=2)
    assert serial_slicer.counts["boolean"] == 14
    assert parallel_slicer.counts == serial_slicer.counts
    for a, b in zip(serial, parallel):
        assert a.height == b.height
        assert a.area == pytest.approx(b.area, rel=1e-12)
        assert len(a.faces) == len(b.faces)
    assert seen[-1] == (len(heights), len(heights))
    assert all(d1 <= d2 for (d1, _), (d2, _) in zip(seen, seen[1:]))


@pytest.mark.parametrize("bad, message", [
    ({"layer": 0.0}, "positive"),
    ({"layer": -1.0}, "positive"),
    ({"heights": [float("nan")]}, "finite"),
    ({"layer": 1.0, "direction": (0, 0, 0)}, "zero vector"),
    ({"layer": 1.0, "chord_tolerance": 0.0}, "chord tolerance"),
])
def test_bad_parameters_are_clear_errors(Part, bad, message):
    with pytest.raises(GeometryError, match=message):
        planar_sections(Part.makeBox(1, 1, 1), **bad)


def test_bad_shapes_are_clear_errors(App, Part):
    with pytest.raises(GeometryError, match="empty"):
        planar_sections(Part.Shape(), layer=1.0)
    shell = Part.makeBox(1, 1, 1).Shells[0]
    with pytest.raises(GeometryError, match="Shell"):
        planar_sections(shell, layer=1.0)
    with pytest.raises(GeometryError, match="not a Part shape"):
        planar_sections("box", layer=1.0)
    face = Part.makePlane(1, 1)
    with pytest.raises(GeometryError, match="not a solid"):
        planar_sections(face, layer=1.0)


def test_invalid_solid_is_a_clear_error(App, Part):
    outer = Part.makeBox(10, 10, 10).Shells[0]
    inner = Part.makeBox(4, 4, 4, App.Vector(8, 8, 8)).Shells[0]  # pokes through the outer
    broken = Part.Solid(Part.makeShell(outer.Faces + inner.Faces))
    assert not broken.isValid()
    with pytest.raises(GeometryError, match="invalid"):
        planar_sections(broken, layer=1.0)


def test_json_form_has_the_documented_fields(Part):
    stack = planar_sections(Part.makeTorus(10, 2), layer=1.0)
    data = stack.to_dict()
    assert data["direction"] == [0.0, 0.0, 1.0]
    layer = data["layers"][2]
    assert set(layer) >= {"height", "area", "centroid", "loops"}
    assert {loop["outer"] for loop in layer["loops"]} == {True, False}
    assert all(len(point) == 2 for loop in layer["loops"] for point in loop["points"])


def _turned_loft(App, Part):
    """A loft through turned ellipses: B-spline faces, whose sections' edges do not survive
    BREP text bit for bit."""
    rings = []
    for z, turn in ((0, 0), (10, 40), (20, 80)):
        ellipse = Part.Ellipse(App.Vector(0, 0, z), 12, 4).toShape()
        ellipse.rotate(App.Vector(0, 0, z), App.Vector(0, 0, 1), turn)
        rings.append(Part.Wire([ellipse]))
    return Part.makeLoft(rings, True, False)


@pytest.mark.parametrize("method", ["fork", "forkserver"])
def test_sections_cut_on_several_processes_are_those_cut_here(App, Part, monkeypatch, method):
    """Which process cuts a job depends on timing; every job's faces, the workers' and this
    process's, come back through OCC's binary format, so the polygons are bit for bit those
    of one process (without that CrankArm's G-code differed from run to run), and a fork
    server's workers, which build the slicer from the solids sent to them, cut the same."""
    from freecad_conformal.geometry import section_pool

    if method == "fork" and section_pool.occ_version() >= section_pool.THREAD_POOL_OCC:
        pytest.skip("OCCT >= 7.8: forked workers may deadlock on its thread pool")
    monkeypatch.setattr(section_pool, "start_method", lambda: method)
    loft = _turned_loft(App, Part)
    heights = [-11.9 + 0.3 * k for k in range(80)]
    expected = PlanarSlicer(loft, (1, 0, 0)).sections(heights, workers=1)
    pooled = PlanarSlicer(loft, (1, 0, 0)).sections(heights, workers=2)
    for want, got in zip(expected, pooled):
        assert want.polygons().equals_exact(got.polygons(), 0.0), want.height
    # Loops made by the processes that cut: the same points, each with its own face's wire,
    # and none discretised here afterwards.
    from freecad_conformal.geometry import sections as sections_module

    def not_here(*_args, **_kwargs):
        raise AssertionError("loops discretised after the cut")

    made = PlanarSlicer(loft, (1, 0, 0)).sections(heights, workers=2, with_loops=True)
    monkeypatch.setattr(sections_module, "loops_of_faces", not_here)
    for want, got in zip(expected, made):
        assert want.polygons().equals_exact(got.polygons(), 0.0), want.height
        wires = [wire for face in got.faces for wire in face.Wires]
        assert [loop.wire.isSame(wire) for loop, wire in zip(got.loops, wires)] == \
            [True] * len(wires)


def test_binary_shapes_come_back_bit_for_bit_where_brep_text_does_not(App, Part):
    """What the workers' sections travel in keeps every real; BREP text rounds them."""
    from freecad_conformal.geometry.occ_binary import faces_from_binary, faces_to_binary

    faces = PlanarSlicer(_turned_loft(App, Part), (1, 0, 0)).section(0.35).faces
    assert faces

    def points(face) -> list:
        return [tuple(p) for edge in face.Edges for p in edge.discretize(20)]

    back = faces_from_binary(faces_to_binary(faces))
    assert [points(f) for f in back] == [points(f) for f in faces]
    assert [f.Area for f in back] == [f.Area for f in faces]
    text = Part.Shape()
    text.importBrepFromString(Part.Compound(faces).exportBrepToString(), False)
    assert [points(f) for f in text.Faces] != [points(f) for f in faces]
    assert faces_from_binary(faces_to_binary([])) == []


def test_one_end_along_a_direction_is_that_end_of_the_extent(App, Part):
    """`lowest_along` and `highest_along` measure one end each (one distance query), the
    values `extent_along` gives: a box's corners and a sphere's poles along a slant."""
    from freecad_conformal.geometry.sections import extent_along, highest_along, lowest_along

    d = np.array([1.0, 2.0, 2.0]) / 3.0
    box = Part.makeBox(10, 20, 30, App.Vector(-5, 0, 4))
    corners = np.array([tuple(v.Point) for v in box.Vertexes]) @ d
    # A box's faces are polygons: each end is its highest vertex, exactly.
    assert (lowest_along(box, d), highest_along(box, d)) == (corners.min(), corners.max())
    sphere = Part.makeSphere(7.0, App.Vector(3, -2, 1))
    centre = np.array([3.0, -2.0, 1.0]) @ d
    assert (lowest_along(sphere, d), highest_along(sphere, d)) == extent_along(sphere, d)
    assert extent_along(sphere, d) == pytest.approx((centre - 7.0, centre + 7.0), abs=1e-7)



def test_ends_read_face_by_face_are_the_nearest_of_all_faces(App, Part):
    """An end is the least distance from a far plane to the faces that may hold it, highest
    box first, stopping where no box reaches further: the same number, bit for bit, as one
    query against the whole solid, on a part whose torus and cylinder boxes overshoot it
    and whose ends mostly lie inside faces, not at vertices (stopping at the first face,
    or at a box instead of a distance, reads another number)."""
    from freecad_conformal.geometry.sections import highest_along, lowest_along

    ring = Part.makeTorus(12.0, 3.0, App.Vector(0, 0, 5), App.Vector(1, 1, 3))
    rod = Part.makeCylinder(2.0, 40.0, App.Vector(-20, 0, 5), App.Vector(1, 0.2, 0.1))
    part = ring.fuse(rod).fuse(Part.makeBox(8, 8, 8, App.Vector(-4, -4, -6)))
    box = part.BoundBox
    centre = np.array([box.Center.x, box.Center.y, box.Center.z])
    size, reach = 4 * box.DiagonalLength, 2 * box.DiagonalLength + np.abs(centre).sum()
    vertices = np.array([tuple(v.Point) for v in part.Vertexes])
    rng = np.random.default_rng(5)
    inside = 0
    for d in list(np.eye(3)) + [v / np.linalg.norm(v) for v in rng.normal(size=(12, 3))]:
        for n in (d, -d):
            u = np.cross(n, [0.0, 0.0, 1.0] if abs(n[2]) < 0.9 else [1.0, 0.0, 0.0])
            u /= np.linalg.norm(u)
            corner = centre + (reach - centre @ n) * n - 0.5 * size * (u + np.cross(n, u))
            far = Part.makePlane(size, size, App.Vector(*corner), App.Vector(*n), App.Vector(*u))
            truth = reach - far.distToShape(part)[0]
            assert highest_along(part, n) == pytest.approx(truth, abs=1e-9)
            assert lowest_along(part, -n) == pytest.approx(-truth, abs=1e-9)
            inside += truth > float((vertices @ n).max()) + 1e-3
    assert inside > 10


def test_a_plane_touching_a_circular_edge_is_cut_by_the_boolean_meanwhile(App, Part, monkeypatch):
    """A plane tangent to the end circle of a rod standing out of a block (its underside,
    5 mm up) leaves the face-by-face cut; where several processes cut, that Boolean is
    expected and made while the other heights are cut, not after them, and the sections
    are those one process cuts, bit for bit."""
    from freecad_conformal.geometry import section_pool

    rod = Part.makeCylinder(5.0, 40.0, App.Vector(0, 0, 10), App.Vector(1, 0, 0))
    part = rod.fuse(Part.makeBox(20, 20, 20, App.Vector(-10, -10, 0))).removeSplitter()
    heights = [0.3 + 0.5 * k for k in range(38)] + [5.0]
    slicer = PlanarSlicer(part, (0, 0, 1))
    assert [h for h, cut in zip(heights, slicer.cut_faces(0, np.array(heights))) if cut is None] \
        == [5.0]
    expected = PlanarSlicer(part, (0, 0, 1)).sections(heights, workers=1)
    calls = []
    real = section_pool._shared

    def shared(slicer, levels, jobs, boolean, *args, **kwargs):
        calls.append((len(jobs), boolean))
        return real(slicer, levels, jobs, boolean, *args, **kwargs)

    monkeypatch.setattr(section_pool, "_shared", shared)
    pooled = PlanarSlicer(part, (0, 0, 1)).sections(heights, workers=2)
    assert calls[0][1][0] is True and calls[0][1].count(True) == 1     # the guess, first
    assert calls[1][0] == 0                                              # no Boolean after
    for want, got in zip(expected, pooled):
        assert want.polygons().equals_exact(got.polygons(), 0.0), want.height
    assert pooled[-1].area > 0


def test_a_layer_plane_at_a_circles_extreme_moves_to_the_side_that_misses_it(App, Part):
    """A layer's sampling plane touching a hole's circular edges at their lowest or highest
    point (a 7.5 mm hole 35 mm up: 27.5 and 42.5 mm, middles of 0.2 mm layers) is moved off
    it to the side where it misses the circles, and is cut face by face. Moved the other
    way it would cross them 1e-4 mm inside their extreme, where the bottle's planes went
    to the Boolean (the chord there lies nearer the face's edge than its domain can tell)."""
    from freecad_conformal.geometry.sections import NEAR_EXTREME, RETRY_NUDGE

    hole = Part.makeCylinder(7.5, 60, App.Vector(-30, 0, 35), App.Vector(1, 0, 0))
    # Turned so that no seam vertex sits at the circles' extremes: the rule is the circles'.
    hole.rotate(App.Vector(0, 0, 35), App.Vector(1, 0, 0), 30.0)
    part = Part.makeBox(40, 30, 50, App.Vector(-20, -15, 0)).cut(hole)
    slicer = PlanarSlicer(part, (0, 0, 1))
    cutter = slicer.cutter(0)
    assert not any(cutter.touches_vertex(h) for h in (27.5, 42.5))
    heights = [0.1 + 0.2 * k for k in range(250)]
    moved = slicer.off_vertices(heights)
    changed = [(round(h, 9), m - h) for h, m in zip(heights, moved) if m != h]
    assert [h for h, _ in changed] == [27.5, 42.5]
    assert [step for _, step in changed] == pytest.approx([-RETRY_NUDGE, RETRY_NUDGE], rel=1e-6)
    slicer.sections(moved)
    assert slicer.counts["boolean"] == 0
    # Just inside an extreme is near it, just outside is not, on either side.
    for extreme, inward in ((27.5, 1.0), (42.5, -1.0)):
        assert cutter.near_circle_extreme(extreme, NEAR_EXTREME)
        assert cutter.near_circle_extreme(extreme + inward * RETRY_NUDGE, NEAR_EXTREME)
        assert not cutter.near_circle_extreme(extreme - inward * RETRY_NUDGE, NEAR_EXTREME)
        assert not cutter.near_circle_extreme(extreme + inward * 3 * RETRY_NUDGE, NEAR_EXTREME)


def test_an_edge_freecad_cannot_name_is_not_straight(App, Part):
    """FreeCAD raises for curve types it has no Python class for: such an edge only makes
    its face no polygon (its ends are then measured by distance), it stops no plan."""
    from freecad_conformal.geometry.plane_curves import STRAIGHT_CURVES, curve_name

    class Unnamed:
        @property
        def Curve(self):
            raise TypeError("undefined curve type")

    assert curve_name(Unnamed()) == ""
    assert curve_name(Part.makeLine(App.Vector(0, 0, 0), App.Vector(1, 0, 0))) in STRAIGHT_CURVES
    assert curve_name(Part.makeCircle(2.0)) == "Circle"


def test_a_section_worker_that_fails_is_reported_while_this_process_cuts(App, Part, monkeypatch):
    """The workers' jobs are read between this process's own: a failure among them is a
    GeometryError naming it, raised then, not after this process has cut the rest."""
    import os

    from freecad_conformal.errors import GeometryError
    from freecad_conformal.geometry import section_pool

    if section_pool.occ_version() >= section_pool.THREAD_POOL_OCC:
        pytest.skip("OCCT >= 7.8: forked workers may deadlock on its thread pool")
    monkeypatch.setattr(section_pool, "start_method", lambda: "fork")
    here, real, cut_here = os.getpid(), section_pool._cut, []

    def cut(*args, **kwargs):
        if os.getpid() != here:
            raise RuntimeError("worker broke")
        cut_here.append(args[1])
        time.sleep(0.05)      # the worker fails meanwhile
        return real(*args, **kwargs)

    monkeypatch.setattr(section_pool, "_cut", cut)
    heights = [0.5 + 0.25 * k for k in range(76)]    # a cone: no section is another's copy
    with pytest.raises(GeometryError, match="section worker failed: RuntimeError: worker broke"):
        PlanarSlicer(Part.makeCone(8, 3, 20)).sections(heights, workers=2)
    # 19 jobs of 4 heights: without reading as it goes, this process cut the 18 left
    assert len(cut_here) <= 5
