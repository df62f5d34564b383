"""Overhang area against closed forms: planar faces exactly, curved faces to 0.5 %."""
from __future__ import annotations

import math

import numpy as np
import pytest

from freecad_conformal.decomposition.decompose import decompose
from freecad_conformal.geometry.overhang import overhang_area, overhang_report

ANGLE = math.radians(45.0)


@pytest.mark.parametrize("radius", [5.0, 12.5])
def test_sphere_cap_below_the_45_degree_line(Part, radius):
    sphere = Part.makeSphere(radius)
    expected = 2 * math.pi * radius ** 2 * (1 - math.cos(ANGLE))
    area = overhang_area(sphere, (0, 0, 1), ANGLE, on_bed=False)
    assert area == pytest.approx(expected, rel=5e-3)


def test_sphere_overhang_is_the_same_in_every_direction(Part):
    sphere = Part.makeSphere(8.0)
    up = overhang_area(sphere, (0, 0, 1), ANGLE, on_bed=False)
    tilted = overhang_area(sphere, (1, 1, 1), ANGLE, on_bed=False)
    assert tilted == pytest.approx(up, rel=5e-3)


def test_inverted_cone_overhangs_only_beyond_its_wall_angle(Part):
    # Wall 45° from the axis, opening upwards: overhangs at a 30° limit, not at 60°.
    cone = Part.makeCone(0.0, 10.0, 10.0)
    wall = cone.Faces[0].Area
    assert overhang_area(cone, (0, 0, 1), math.radians(30), on_bed=False) == pytest.approx(wall, rel=1e-9)
    assert overhang_area(cone, (0, 0, 1), math.radians(60), on_bed=False) == pytest.approx(0.0, abs=1e-6)


def test_box_on_the_bed_has_no_overhang_and_its_ceiling_when_lifted(Part):
    box = Part.makeBox(10, 20, 5)
    assert overhang_area(box, (0, 0, 1), ANGLE) == 0.0
    report = overhang_report(box, (0, 0, 1), ANGLE, on_bed=False)
    assert report.area == pytest.approx(200.0)
    assert len(report.faces) == 1


def test_a_reversed_solid_overhangs_where_its_faces_point_down(App, Part):
    """A box with a round bore along X, built along +Z off the bed: its floor and the
    bore's upper quarter overhang, listed by face index. The same box reversed (its normals
    point inward) is scanned again, not read from the first: its ceiling faces down
    instead. Planar faces are looked up by normal in one product per direction
    (`overhang._planar_table`), curved ones on their mesh."""
    box = Part.makeBox(20, 10, 10).cut(Part.makeCylinder(3.0, 20.0, App.Vector(0, 5, 5), App.Vector(1, 0, 0)))
    bore = next(i for i, f in enumerate(box.Faces) if type(f.Surface).__name__ == "Cylinder")
    ceiling = next(i for i, f in enumerate(box.Faces) if abs(f.CenterOfMass.z - 10) < 1e-9)
    floor = next(i for i, f in enumerate(box.Faces) if abs(f.CenterOfMass.z) < 1e-9)
    quarter = 2 * math.pi * 3.0 * 20.0 / 4
    outward = overhang_report(box, (0, 0, 1), ANGLE, on_bed=False)
    assert [i for i, _ in outward.faces] == sorted([floor, bore])
    assert dict(outward.faces)[floor] == pytest.approx(200.0, rel=1e-9)
    assert dict(outward.faces)[bore] == pytest.approx(quarter, rel=5e-3)
    inward = overhang_report(box.reversed(), (0, 0, 1), ANGLE, on_bed=False)
    assert [i for i, _ in inward.faces] == sorted([ceiling, bore])
    assert inward.area == pytest.approx(200.0 + quarter, rel=5e-3)


def test_cylinder_built_sideways_overhangs_on_its_lower_quarter(Part):
    # Axis along X, built along +Z: the lateral strip with n·z < −sin 45° spans 90° of 360°.
    cylinder = Part.makeCylinder(5.0, 20.0, Part.Vertex(0, 0, 0).Point, Part.Vertex(1, 0, 0).Point)
    lateral = 2 * math.pi * 5.0 * 20.0
    area = overhang_area(cylinder, (0, 0, 1), ANGLE, on_bed=False)
    assert area == pytest.approx(lateral / 4, rel=5e-3)


def _twisted_blade(App, Part):
    """A blade lofted through three cambered, twisted profiles (thin, with rounded edges), as
    a fan's: BRepMesh leaves long triangles from its edges onto its flats."""
    sections = []
    for radius, twist, chord in ((7.0, 35.0, 9.0), (19.0, 25.0, 8.0), (30.0, 15.0, 6.0)):
        t = math.radians(twist)
        front = [App.Vector(radius, chord * s * math.cos(t),
                            chord * s * math.sin(t) + 0.8 * (1 - 4 * s * s))
                 for s in (-0.5, -0.25, 0.0, 0.25, 0.5)]
        back = [App.Vector(radius, p.y, p.z - 1.2) for p in reversed(front)]
        curve = Part.BSplineCurve()
        curve.interpolate(front + back + [front[0]], PeriodicFlag=False)
        sections.append(Part.Wire(curve.toShape()))
    return Part.makeLoft(sections, True, False)


def _grid_overhang(face, d, threshold: float, n: int) -> float:
    """Overhang of a face by the midpoint rule on an n x n grid of its (u, v) box, with OCC's
    exact normals and area elements: slow, and independent of any mesh."""
    u0, u1, v0, v1 = face.ParameterRange
    du, dv = (u1 - u0) / n, (v1 - v0) / n
    step = 1e-6
    total = 0.0
    for i in range(n):
        u = u0 + (i + 0.5) * du
        for j in range(n):
            v = v0 + (j + 0.5) * dv
            if not face.isPartOfDomain(u, v):
                continue
            if tuple(face.normalAt(u, v)) @ d >= -threshold:
                continue
            p = face.valueAt(u, v)
            element = (face.valueAt(u + step, v) - p).cross(face.valueAt(u, v + step) - p)
            total += element.Length / step ** 2 * du * dv
    return total


@pytest.mark.parametrize("down", [True, False])
def test_twisted_blade_overhang_matches_its_surface(App, Part, down):
    import numpy as np

    from freecad_conformal.geometry.surface_mesh import face_part, mesh_deflection

    blade = _twisted_blade(App, Part)
    d = np.array([0.0, 0.0, -1.0 if down else 1.0])
    threshold = math.sin(ANGLE)
    curved = [face for face in blade.Faces if type(face.Surface).__name__ != "Plane"]
    meshed = sum(face_part(face, mesh_deflection(blade)).below(d, threshold) for face in curved)
    surface = sum(_grid_overhang(face, d, threshold, 100) for face in curved)
    # Built along -Z the corners' normals read 164.8 mm² of the surface's 181.8 (-9 %):
    # the long triangles off its trailing edge. Along +Z they read 1.7 % high.
    assert meshed == pytest.approx(surface, rel=0.01 if down else 0.03)


def test_the_best_single_direction_may_stand_a_turned_part_on_a_face(App, Part):
    """A block with a hole through it, turned off every axis: the best single direction
    stands it on a face (the hole then runs upright, no overhang), not on one of the six
    axes of the file's frame; and a direction that balances it on a corner is never taken,
    however little it overhangs."""
    from freecad_conformal.geometry.overhang import (AXIS_DIRECTIONS, MIN_BASE_AREA,
                                                     base_area, best_single_direction)

    V = App.Vector
    block = Part.makeBox(30, 20, 10).cut(Part.makeCylinder(3, 10, V(15, 10, 0)))
    block.rotate(V(0, 0, 0), V(1, 2, 0), 40)
    direction, area = best_single_direction(block, ANGLE)
    _, axis_area = best_single_direction(block, ANGLE, AXIS_DIRECTIONS)
    assert axis_area > 100.0
    assert area == pytest.approx(0.0, abs=1e-6)
    assert base_area(block, direction) >= MIN_BASE_AREA
    assert min(abs(float(direction @ axis)) for axis in AXIS_DIRECTIONS) < 0.99


def test_the_best_single_direction_never_balances_a_part_on_a_corner():
    """The jack has no overhang along its cube's corners, where it touches the bed at a
    point: a planar slicer could not print it so, and neither can the plan."""
    from freecad_conformal.geometry import samples
    from freecad_conformal.geometry.overhang import (MIN_BASE_AREA, base_area,
                                                     best_single_direction, overhang_area)

    jack = samples.jack()
    assert overhang_area(jack, np.ones(3) / math.sqrt(3.0), ANGLE) == pytest.approx(0.0, abs=1e-6)
    direction, area = best_single_direction(jack, ANGLE)
    assert area > 100.0
    assert base_area(jack, direction) >= MIN_BASE_AREA


def test_a_large_round_bottom_still_overhangs_on_the_bed(Part):
    """Only what runs out little is laid on the bed: a 12.5 mm ball runs out 4.5 mm by
    0.4 mm above it, and keeps its cap, seen from its pole's triangles or its equator's
    alike (a rim of fillet is laid: below)."""
    radius = 12.5
    sphere = Part.makeSphere(radius, Part.Vertex(0, 0, radius).Point)
    cap = 2 * math.pi * radius ** 2 * (1 - math.cos(ANGLE))
    assert overhang_area(sphere, (0, 0, 1), ANGLE, on_bed=False) == pytest.approx(cap, rel=5e-3)
    for turn in (0, 90):
        turned = sphere.copy()
        turned.rotate(Part.Vertex(0, 0, radius).Point, Part.Vertex(1, 0, 0).Point, turn)
        assert overhang_area(turned, (0, 0, 1), ANGLE) == pytest.approx(cap, rel=5e-3)


def test_a_box_rounded_on_every_edge_stands_flat_without_support(Part):
    """The lower half of a 1 mm fillet rises 0.29 mm: counted as overhang, it left 66.2 mm²
    "to support" and the plan turned the box on its end (200 layers, not 75)."""
    box = Part.makeBox(40, 30, 15)
    rounded = box.makeFillet(1.0, box.Edges)
    assert overhang_area(rounded, (0, 0, 1), ANGLE) < 1e-3
    assert overhang_area(rounded, (0, 0, 1), ANGLE, on_bed=False) > 90.0   # the whole rim
    plan = decompose(rounded, root_direction="auto")
    assert plan.support_area < 1e-3
    assert abs(plan.subparts[0].build_direction[2]) == pytest.approx(1.0)


def test_a_steep_chamfer_in_the_band_rests_and_a_shallow_recess_still_overhangs(App, Part):
    """A 60° chamfer 0.2 mm high along the bottom is laid on the bed; the ceiling of a
    0.2 mm recess in the bottom is a bridge, as before."""
    V = App.Vector
    box = Part.makeBox(20, 20, 10)
    bottom = [e for e in box.Edges if abs(e.BoundBox.ZMax) < 1e-9]
    # 0.2 mm up, 0.35 mm across: its faces lean 60° from the walls, 30° from the bed
    chamfered = box.makeChamfer(0.2, 0.2 * math.tan(math.radians(60)), bottom)
    sloping = [f for f in chamfered.Faces if -0.99 < f.normalAt(0, 0).z < -math.sin(ANGLE)]
    assert len(sloping) == 4
    assert max(f.BoundBox.ZMax for f in sloping) == pytest.approx(0.2)
    assert overhang_area(chamfered, (0, 0, 1), ANGLE) == 0.0
    lifted = (20 - 0.4 * math.tan(math.radians(60))) ** 2 + sum(f.Area for f in sloping)
    assert overhang_area(chamfered, (0, 0, 1), ANGLE, on_bed=False) == pytest.approx(lifted)
    recessed = box.cut(Part.makeBox(10, 10, 0.2, V(5, 5, 0)))
    assert overhang_area(recessed, (0, 0, 1), ANGLE) == pytest.approx(100.0)


def test_the_beds_level_is_read_only_for_overhang_near_the_bed(App, Part, monkeypatch):
    """Reading the bed's level is a pass over every curved face's mesh (3 ms a direction on
    Pump_Nut, a fifth of its scan of 30 directions): a cap far above the lowest vertex is not
    laid whatever that level, and keeps its overhang without it."""
    from freecad_conformal.geometry import overhang

    read: list[int] = []
    original = overhang._bed_level
    monkeypatch.setattr(overhang, "_bed_level", lambda *args: read.append(1) or original(*args))
    radius = 6.0
    ball = Part.makeSphere(radius, App.Vector(0, 0, 30.0))
    post = Part.makeCylinder(2.0, 30.0 - radius + 1.0)
    on_a_post = post.fuse(ball).removeSplitter()
    report = overhang_report(on_a_post, (0, 0, 1), ANGLE)
    assert report.area > 10.0 and not report.laid
    assert not read
    box = Part.makeBox(40, 30, 15)
    report = overhang_report(box.makeFillet(1.0, box.Edges), (0, 0, 1), ANGLE)
    assert report.area < 1e-3 and report.laid and read


def _ring(App, Part, on_edge: bool):
    """A ring (torus R 20, r 4): lying flat it rests on an annulus, on its edge on a spot."""
    ring = Part.makeTorus(20.0, 4.0)
    if on_edge:
        ring.rotate(App.Vector(0, 0, 0), App.Vector(1, 0, 0), 90.0)
    return ring


def test_a_ring_on_its_edge_does_not_stand_and_a_bar_on_its_side_does(App, Part):
    """A part stands on a flat face or on a first layer of MIN_BASE_AREA: a ring on its edge
    rests on 6 mm² (its 48 mm above it tip or peel off), a round bar on its side on a
    strip along its length."""
    from freecad_conformal.geometry.overhang import MIN_BASE_AREA, footprint_area, stands

    ring = _ring(App, Part, on_edge=False)
    # At 0.1 mm up its outer rim is an ellipse of half-axes √(2·4·0.1) and √(2·24·0.1).
    spot = math.pi * math.sqrt(2 * 4 * 0.1) * math.sqrt(2 * 24 * 0.1)
    assert footprint_area(ring, (1, 0, 0)) == pytest.approx(spot, rel=0.02)
    assert footprint_area(ring, (0, 0, 1)) > 10 * MIN_BASE_AREA
    assert not stands(ring, (1, 0, 0)) and stands(ring, (0, 0, 1))
    bar = Part.makeCylinder(5.0, 60.0, App.Vector(0, 0, 0), App.Vector(1, 0, 0))
    assert stands(bar, (0, 0, 1)) and stands(bar, (1, 0, 0))


def test_the_best_single_direction_stands_where_the_part_can(App, Part):
    """On its edge the ring keeps 319 mm² of overhang, lying flat 789 mm²: it lies flat. A
    ball stands nowhere: its least overhang, as before."""
    from freecad_conformal.geometry.overhang import AXIS_DIRECTIONS, best_single_direction

    ring = _ring(App, Part, on_edge=False)
    direction, area = best_single_direction(ring, ANGLE)
    assert abs(direction[2]) == pytest.approx(1.0)
    assert area == pytest.approx(overhang_area(ring, (0, 0, 1), ANGLE))
    assert area > 2 * overhang_area(ring, (1, 0, 0), ANGLE)
    ball = Part.makeSphere(10.0)
    direction, area = best_single_direction(ball, ANGLE, AXIS_DIRECTIONS)
    assert area == pytest.approx(min(overhang_area(ball, d, ANGLE) for d in AXIS_DIRECTIONS))


@pytest.mark.parametrize("on_edge", [False, True])
def test_a_ring_is_planned_lying_flat_however_it_was_modelled(App, Part, on_edge):
    """Turning it on its edge saves overhang, but it would rest on a spot; modelled on its
    edge, it is laid flat, and the plan says why."""
    ring = _ring(App, Part, on_edge)
    plan = decompose(ring, root_direction="auto")
    root = plan.subparts[plan.order[0]]
    up = np.array([0.0, 1.0, 0.0]) if on_edge else np.array([0.0, 0.0, 1.0])
    assert abs(float(root.build_direction @ up)) == pytest.approx(1.0)
    assert plan.support_area == pytest.approx(overhang_area(ring, up, ANGLE), rel=1e-6)
    assert any("as placed it would rest on" in note for note in plan.notes) == on_edge
