"""Face-by-face sections (the fast path) against the Boolean, and plane ∩ torus in closed form."""
from __future__ import annotations

import math

import numpy as np
import pytest

from freecad_conformal.geometry import samples
from freecad_conformal.geometry.face_sections import FaceCutter
from freecad_conformal.geometry.loops import dense_area, dense_area_centroid
from freecad_conformal.geometry.sections import PlanarSlicer, uniform_heights
from freecad_conformal.geometry.solids import load_shape
from freecad_conformal.geometry.torus_sections import FIT_TOLERANCE, torus_plane_curves

#: OCC integrates the area of faces bounded by high-degree B-splines to about this
#: (measured up to 3.7e-4 on the Boolean's own CrankArm faces against a dense polygon).
AREA_REL = 5e-4

#: Imported models' edges sit up to 1.3e-4 mm off their faces; on a 0.6 mm² section near
#: the screw's tip the two results differ by 4e-4 mm² (both loops within that of the part).
AREA_ABS = 1e-3

#: Chord tolerance (mm) of the polygons whose symmetric difference compares the two results:
#: a missing island or a wrong piece shows as mm², matching loops as slivers of at most
#: CHORD × perimeter (each result's polygon is its own discretisation of the same curves).
CHORD = 1e-3


def _compare(shape, direction, spacing):
    """Per layer: (height, fast section or None, Boolean section)."""
    fast = PlanarSlicer(shape, direction, CHORD)
    boolean = PlanarSlicer(shape, direction, CHORD, face_by_face=False)
    heights = uniform_heights(shape, fast.frame.n, spacing)
    cutters = [FaceCutter(solid, fast.frame.n) for solid in fast.solids]
    rows = []
    for height, reference in zip(heights, boolean.sections(heights)):
        results = [cutter.section_faces(height) for cutter in cutters]
        items = None if any(r is None for r in results) else [i for r in results for i in r]
        rows.append((height, None if items is None else fast.make_section(height, items), reference))
    return rows


@pytest.mark.slow
@pytest.mark.parts
@pytest.mark.parametrize("name, direction", [
    ("Pump_Nut.brep", (0, 0, 1)), ("Pump_Nut.brep", (0.3, -0.5, 0.8)),
    ("bottle.brep", (1, 0, 0)), ("CrankArm.brep", (0, 0, 1)), ("CrankArm.brep", (1, 1, 1)),
    ("MODERN_Table_1.brep", (1, 1, 1)), ("screw.step", (0, 0, 1)), ("screw.step", (1, 0, 0)),
    ("screw.step", (0.3, -0.5, 0.8)),
    ("sliced_cylinder.step", (1, 0, 0)), ("revolved_sphere.step", (1, 0, 0)),
])
def test_face_by_face_sections_match_the_boolean(parts_dir, name, direction):
    shape = load_shape(parts_dir / name)
    _assert_match(_compare(shape, direction, spacing=1.3), least=0.5, shape=shape)


def _assert_match(rows, least: float, shape=None) -> None:
    """At least `least` of the layers cut face by face, each matching the Boolean; where
    the two differ in faces, and `shape` is given, the fast one matches a fine mesh's
    section (`_mesh_truth`: the Boolean errs too)."""
    done = [(h, fast, ref) for h, fast, ref in rows if fast is not None]
    assert len(done) >= least * len(rows), f"only {len(done)} of {len(rows)} layers face by face"
    for height, fast, reference in done:
        if shape is not None and len(fast.faces) != len(reference.faces):
            count, area = _mesh_truth(shape, fast.frame.n, height)
            assert len(fast.faces) == count != len(reference.faces), height
            assert fast.area == pytest.approx(area, rel=MESH_AREA_REL), height
            continue
        assert len(fast.faces) == len(reference.faces), height
        if reference.area > 0:
            difference = fast.polygons().symmetric_difference(reference.polygons()).area
            bound = CHORD * reference.polygons().length + 1e-3 * reference.area
            assert difference <= bound, (height, difference, bound)
        area, centroid = reference.area, reference.centroid
        if not _agree(fast, area, centroid):
            area, centroid = _dense_truth(reference)   # the Boolean's own integral may err
        assert fast.area == pytest.approx(area, rel=AREA_REL, abs=AREA_ABS), height
        assert _agree(fast, area, centroid), (height, fast.centroid, centroid)


#: Deflection (mm) of the fine mesh that settles a disagreement, and how close its
#: section's area comes (its chords cut the curved boundary: 111.64 at 0.01 mm, 111.62 at
#: 0.003 on the bottle's 111.70 mm² section along X at 7.25).
MESH_DEFLECTION = 0.003
MESH_AREA_REL = 2e-3


def _mesh_truth(shape, normal, height: float) -> tuple[int, float]:
    """(polygons, area) of the plane n·p = height through a fine triangle mesh of `shape`:
    each triangle's crossing segment, chained into loops, filled even-odd."""
    from shapely import line_merge
    from shapely.geometry import MultiLineString, Polygon

    from freecad_conformal.geometry.frames import LayerFrame

    points, triangles = shape.tessellate(MESH_DEFLECTION)
    p = np.array([tuple(v) for v in points])
    t = np.asarray(triangles, dtype=int)
    frame = LayerFrame.for_direction(np.asarray(normal, dtype=float))
    g = p @ frame.n - height
    segments = []
    for tri in t:
        ends = []
        for a, b in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])):
            if (g[a] < 0) != (g[b] < 0):
                x = p[a] + (p[b] - p[a]) * (g[a] / (g[a] - g[b]))
                ends.append((round(float(x @ frame.u), 9), round(float(x @ frame.v), 9)))
        if len(ends) == 2 and ends[0] != ends[1]:
            segments.append(ends)
    region = None
    merged = line_merge(MultiLineString(segments))
    for loop in getattr(merged, "geoms", [merged]):
        polygon = Polygon(loop.coords).buffer(0)
        region = polygon if region is None else region.symmetric_difference(polygon)
    return len(getattr(region, "geoms", [region])), float(region.area)


def _agree(fast, area: float, centroid) -> bool:
    if area <= 0:       # an empty section has no centroid
        return fast.area == 0
    return (fast.area == pytest.approx(area, rel=AREA_REL, abs=AREA_ABS)
            and np.allclose(fast.centroid, centroid, atol=1e-3 * math.sqrt(area)))


def _dense_truth(reference):
    """The Boolean section's area and centroid from its wires sampled densely, independent
    of OCC's boundary integrals: those err where a wire has gaps within its edges'
    tolerances (the bottle's neck along X: 0.034 mm² and 0.012 mm off)."""
    area, uv = dense_area_centroid(reference.faces, reference.frame)
    return area, reference.frame.to_3d(uv[None, :], reference.height)[0]


@pytest.mark.parts
def test_the_nut_is_cut_face_by_face_on_every_layer(parts_dir):
    """The benchmark part whose tori made the Boolean slow takes no fallback at all."""
    shape = load_shape(parts_dir / "Pump_Nut.brep")
    slicer = PlanarSlicer(shape, (0, 0, 1))
    slicer.sections(uniform_heights(shape, slicer.frame.n, 0.5))
    assert slicer.counts["boolean"] == 0 and slicer.counts["face_by_face"] > 100


def test_a_plane_through_a_vertex_falls_back_to_the_boolean(App, Part):
    box = Part.makeBox(10, 20, 30)
    wedge = box.cut(Part.makeBox(10, 10, 10, App.Vector(0, 10, 20)))
    slicer = PlanarSlicer(wedge, (0, 0, 1))
    exact = slicer.sections([20.0, 5.0])        # 20: on the step's vertices and face
    assert slicer.counts == {"face_by_face": 1, "boolean": 1}
    assert exact[0].area == pytest.approx(100.0, rel=1e-12) or exact[0].area == pytest.approx(200.0, rel=1e-12)
    assert exact[1].area == pytest.approx(200.0, rel=1e-12)


def test_holes_and_islands_are_nested_by_depth(App, Part):
    """One solid (a pot with a post): a ring, and an island inside its hole."""
    groove = Part.makeCylinder(15, 8, App.Vector(0, 0, 2)).cut(Part.makeCylinder(10, 8, App.Vector(0, 0, 2)))
    pot = Part.makeCylinder(20, 10).cut(groove)
    slicer = PlanarSlicer(pot, (0, 0, 1))
    section = slicer.section(5.0)
    assert slicer.counts == {"face_by_face": 1, "boolean": 0}
    assert section.area == pytest.approx(math.pi * (400 - 225 + 100), rel=1e-12)
    assert sorted(len(face.Wires) for face in section.faces) == [1, 2]
    assert np.allclose(section.centroid, [0, 0, 5], atol=1e-9)


def _torus_points_error(curves, torus, n, height):
    centre = np.array(tuple(torus.Center))
    w = np.array(tuple(torus.Axis))
    worst = 0.0
    for curve in curves:
        for t in np.linspace(curve.FirstParameter, curve.LastParameter, 401):
            p = np.array(tuple(curve.value(t)))
            along = (p - centre) @ w
            radial = np.linalg.norm(p - centre - along * w)
            worst = max(worst, abs(math.hypot(radial - torus.MajorRadius, along) - torus.MinorRadius),
                        abs(p @ n - height))
    return worst


@pytest.mark.parametrize("normal, height", [
    ((1, 0, 0), 3.0), ((1, 0, 0), 0.5), ((0.6, 0, 0.8), 1.0), ((0.3, -0.5, 0.8), -2.0),
    ((1, 0, 0), 11.5),
])
def test_torus_curves_lie_on_torus_and_plane_and_match_occ(App, Part, normal, height):
    torus = Part.Toroid()
    torus.MajorRadius, torus.MinorRadius = 10.0, 2.0
    n = np.asarray(normal, float) / np.linalg.norm(normal)
    curves = torus_plane_curves(torus, n, height)
    assert curves
    assert _torus_points_error(curves, torus, n, height) <= FIT_TOLERANCE
    occ = torus.intersectSS(Part.Plane(App.Vector(*(height * n)), App.Vector(*n)))
    assert sum(c.length() for c in curves) == pytest.approx(sum(c.length() for c in occ), rel=1e-6)


@pytest.mark.parts
def test_spindle_torus_curves_lie_on_it_and_match_occ(App, Part, parts_dir):
    """The screw's domed head is a spindle torus (R 8.25 < r 54.87), which OCC walks even
    square to its axis: its circles and its slanted sections in closed form, on both sheets
    (the head is the inner one, across the axis), as long as OCC's, through its faces."""
    head = [face for face in load_shape(parts_dir / "screw.step").Faces
            if type(face.Surface).__name__ == "Toroid"]
    assert head and all(f.Surface.MajorRadius < f.Surface.MinorRadius for f in head)
    torus = head[0].Surface
    centre, w = np.array(tuple(torus.Center)), np.array(tuple(torus.Axis))
    R, r = torus.MajorRadius, torus.MinorRadius
    checked = 0
    for face in head:
        u0, u1, v0, v1 = face.ParameterRange
        through = np.array(tuple(face.Surface.value(0.5 * (u0 + u1), 0.5 * (v0 + v1))))
        for normal in (w, (1, 0.35, 0), (0.3, 0.2, 0.93)):
            n = np.asarray(normal, float) / np.linalg.norm(normal)
            height = float(through @ n)
            curves = torus_plane_curves(torus, n, height)
            assert curves, (normal, height)
            for curve in curves:
                for t in np.linspace(curve.FirstParameter, curve.LastParameter, 201):
                    p = np.array(tuple(curve.value(t)))
                    along = (p - centre) @ w
                    radial = np.linalg.norm(p - centre - along * w)
                    off = min(abs(math.hypot(radial - R, along) - r), abs(math.hypot(radial + R, along) - r))
                    assert off <= FIT_TOLERANCE and abs(p @ n - height) <= FIT_TOLERANCE
            occ = torus.intersectSS(Part.Plane(App.Vector(*(height * n)), App.Vector(*n)))
            assert sum(c.length() for c in curves) == pytest.approx(sum(c.length() for c in occ), rel=1e-6)
            checked += 1
    assert checked == 3 * len(head)


def test_torus_cases_occ_solves_in_closed_form_are_left_to_it(Part):
    torus = Part.Toroid()
    torus.MajorRadius, torus.MinorRadius = 10.0, 2.0
    assert torus_plane_curves(torus, np.array([0.0, 0.0, 1.0]), 1.0) is None  # normal to the axis
    assert torus_plane_curves(torus, np.array([1.0, 0.0, 0.0]), 0.0) is None  # contains the axis


@pytest.mark.slow
@pytest.mark.parametrize("mirrored", [False, True])
def test_torus_segment_sections_match_the_boolean_in_a_mirrored_frame_too(App, Part, mirrored):
    """Three quarters of a torus: faces trimmed in u (and u running backwards once mirrored)."""
    solid = Part.makeTorus(10, 2, App.Vector(0, 0, 0), App.Vector(0, 0, 1), 0, 360, 270)
    if mirrored:
        solid = solid.mirror(App.Vector(0, 0, 0), App.Vector(1, 0, 0))
    assert any(type(f.Surface).__name__ == "Toroid" for f in solid.Faces)
    for direction in ((1, 0.2, 0.1), (0.3, -0.5, 0.8)):
        rows = _compare(solid, direction, spacing=0.7)
        done = [(fast, reference) for _, fast, reference in rows if fast is not None]
        assert len(done) >= 0.8 * len(rows)
        for mine, reference in done:
            # OCC's area of the Boolean's faces (walked curves) is off by up to 2.6e-4 of
            # a dense polygon on its own wires; ours agrees with that polygon to 1e-7.
            assert mine.area == pytest.approx(dense_area(reference.faces, reference.frame), rel=5e-6, abs=1e-9)
            assert len(mine.faces) == len(reference.faces)


@pytest.mark.parts
@pytest.mark.parametrize("name, direction, least", [
    ("sliced_cylinder.step", (1, 0, 0), 1.0), ("sliced_cylinder.step", (0, 1, 0), 1.0),
    ("bottle.brep", (1, 0, 0), 0.97),
    ("revolved_sphere.step", (1, 0, 0), 1.0),
])
def test_edges_off_their_faces_by_their_tolerance_are_cut_face_by_face(parts_dir, name, direction,
                                                                      least):
    """Elliptic arcs and thread edges stored with tolerances up to 2e-2 mm: their crossings
    lie off the plane∩face curves by more than ON_CURVE (every sliced_cylinder layer along X
    and a quarter of the bottle's went to the Boolean). Spheres across their seam (OCC
    answers two arcs whose ends cross no edge: half the sphere's layers along X) and torus
    curves outside faces that do not fill their (u, v) box (the bottle's side blends).
    Where the plane meets the face at a slant the crossing lies further off, tolerance /
    sin θ (sliced_cylinder's leaning cylinders across their axis: 97 of 1,000 layers)."""
    shape = load_shape(parts_dir / name)
    slicer = PlanarSlicer(shape, direction)
    slicer.sections(uniform_heights(shape, slicer.frame.n, 0.3))
    done, total = slicer.counts["face_by_face"], sum(slicer.counts.values())
    assert done >= least * total, slicer.counts


@pytest.mark.slow
@pytest.mark.parts
def test_crossings_of_slanted_faces_match_the_boolean(parts_dir):
    """The sliced cylinder across its axis, where crossings lie off their curves by the
    edge tolerance over the slant: every layer face by face, each the Boolean's."""
    shape = load_shape(parts_dir / "sliced_cylinder.step")
    _assert_match(_compare(shape, (0, 1, 0), spacing=1.3), least=1.0, shape=shape)


def test_pieces_walked_from_their_far_end_join_into_a_closed_wire(App, Part):
    """The unit square from three pieces, the middle one listed from the end the walk
    reaches last: its edges must be added in reverse, or the wire breaks open."""
    from freecad_conformal.geometry.planar_faces import faces_from_pieces

    def segment(a, b):
        return Part.LineSegment(App.Vector(*a, 0), App.Vector(*b, 0)).toShape()

    bottom = ([segment((0, 0), (1, 0))], 0, 1)
    right = ([segment((1, 1), (1, 0.5)), segment((1, 0.5), (1, 0))], 2, 1)
    top_left = ([segment((1, 1), (0, 1)), segment((0, 1), (0, 0))], 2, 0)
    faces = faces_from_pieces([bottom, right, top_left], 3, Part.Plane(App.Vector(), App.Vector(0, 0, 1)))
    assert faces is not None and [f.area for f in faces] == [pytest.approx(1.0, rel=1e-12)]


def test_a_face_winding_twice_round_its_cylinder_holds_points_of_its_second_turn(App, Part):
    """A helical strip: u from 0 to 4π, v rising 8 mm over it, 2 mm wide. Above the angle π
    it covers z 2..4 (first turn) and 6..8 (second); folding u into one period (as OCC's
    own classifier does) loses the second turn."""
    from FreeCAD import Base

    from freecad_conformal.geometry.uv_domain import FaceDomain

    cylinder = Part.Cylinder()
    cylinder.Radius = 10
    corners = [(0, 0), (4 * math.pi, 8), (4 * math.pi, 10), (0, 2)]
    edges = [Part.Geom2d.Line2dSegment(Base.Vector2d(*corners[i]), Base.Vector2d(*corners[i - 3]))
             .toShape(cylinder) for i in range(4)]
    strip = Part.Face(cylinder, Part.Wire(edges))
    strip.validate()    # orients the wire so that the strip, not its complement, is the face
    assert strip.Area == pytest.approx(4 * math.pi * 10 * 2, rel=1e-9)
    domain = FaceDomain(strip)
    verdicts = {z: domain.contains(App.Vector(-10, 0, z)) for z in (3, 5, 7, 9)}
    assert verdicts == {3: True, 5: False, 7: True, 9: False}


def _profile(App, x: float, twist: float, chord: float) -> tuple[list, list]:
    """A cambered blade section at `x`: its front points, then its back ones reversed."""
    t = math.radians(twist)
    front = [App.Vector(x, chord * s * math.cos(t), chord * s * math.sin(t) + 1 - 4 * s * s)
             for s in (-0.5, -0.25, 0.0, 0.25, 0.5)]
    return front, [App.Vector(x, p.y, p.z - 1.5) for p in reversed(front)]


def _blade(App, Part, sections):
    """A closed cambered profile (one non-periodic B-spline, so one lateral face with a
    seam) lofted through (x, twist°, chord) sections."""
    wires = []
    for section in sections:
        front, back = _profile(App, *section)
        curve = Part.BSplineCurve()
        curve.interpolate(front + back + [front[0]], PeriodicFlag=False)
        wires.append(Part.Wire(curve.toShape()))
    return Part.makeLoft(wires, True, False)


@pytest.mark.parametrize("direction", [(0, 0, 1), (0, 1, 0), (0.3, -0.5, 0.8)])
def test_curves_walked_across_a_seam_join_there(App, Part, direction):
    """OCC walks a plane ∩ the blade's face as curves that stop at its seam and go on from
    the other side: their ends join at the seam crossing (11 of 27 layers along Z, 20 of
    36 askew went to the Boolean)."""
    blade = _blade(App, Part, ((0.0, 40.0, 10.0), (12.0, 20.0, 8.0), (24.0, 0.0, 6.0)))
    _assert_match(_compare(blade, direction, spacing=0.3), least=1.0)


@pytest.mark.parametrize("direction", [(1, 0, 0), (0, 1, 0)])
def test_sections_of_high_degree_splines_have_their_exact_area(App, Part, direction):
    """A loft through four turned ellipses has degree-12 B-spline faces: OCC integrated
    a section's area 2 % off with many knot spans in one edge (the Boolean's answer and a
    dense polygon agree)."""
    rings = []
    for z, turn, a, b in ((0, 0, 12, 4), (10, 40, 10, 5), (20, 80, 14, 3), (30, 120, 12, 4)):
        ellipse = Part.Ellipse(App.Vector(0, 0, z), a, b).toShape()
        ellipse.rotate(App.Vector(0, 0, z), App.Vector(0, 0, 1), turn)
        rings.append(Part.Wire([ellipse]))
    twisted = Part.makeLoft(rings, True, False)
    _assert_match(_compare(twisted, direction, spacing=0.7), least=1.0)


def _two_face_blade(App, Part):
    """A blade whose profile is two B-spline edges (front and back), so its side is two
    faces meeting along span-wise edges that are not seams, trimmed to x 4..20 so that its
    faces are parts of their surfaces (as a decomposition's cuts leave them)."""
    wires = []
    for section in ((0.0, 40.0, 10.0), (12.0, 20.0, 8.0), (24.0, 0.0, 6.0)):
        front, back = _profile(App, *section)
        halves = []
        for points in (front, [front[-1], *back, front[0]]):
            curve = Part.BSplineCurve()
            curve.interpolate(points)
            halves.append(curve.toShape())
        wires.append(Part.Wire(halves))
    loft = Part.makeLoft(wires, True, False)
    return loft.common(Part.makeBox(16, 40, 40, App.Vector(4, -20, -20))).Solids[0]


def test_curves_ending_together_on_a_crossing_each_end_there(App, Part, monkeypatch):
    """OCC may answer a plane ∩ B-spline face with two walked curves that both end on a
    crossing of the face's edge (the fan's hub: 45 of its 1,009 sections went to the
    Boolean). Here every curve through a crossing is split there, as OCC split those:
    the crossing must end both, and the sections still match the Boolean."""
    import freecad_conformal.geometry.face_sections as face_sections

    blade = _two_face_blade(App, Part)
    assert [type(f.Surface).__name__ for f in blade.Faces].count("BSplineSurface") == 2
    # whole surfaces, so that OCC's curves run through the crossings to be split there
    monkeypatch.setattr(face_sections, "TRIM_SHARE", 0.0)
    occ_curves = face_sections.surface_curves
    splits = []

    def split_at_crossings(surface, parameter_range, plane, n, height):
        curves = occ_curves(surface, parameter_range, plane, n, height)
        if not curves:
            return curves
        disc = Part.Plane(App.Vector(*(height * np.asarray(n))), App.Vector(*n))
        crossings = [p for edge in blade.Edges for p in edge.Curve.intersectCS(disc)[0]]
        result = []
        for curve in curves:
            cut = curve
            for point in crossings:
                at = App.Vector(point.X, point.Y, point.Z)
                t = cut.parameter(at)
                inside = cut.FirstParameter + 1e-6 < t < cut.LastParameter - 1e-6
                if (isinstance(cut, Part.BSplineCurve) and inside
                        and (cut.value(t) - at).Length < 1e-7):
                    first, second = cut.copy(), cut.copy()
                    first.segment(cut.FirstParameter, t)
                    second.segment(t, cut.LastParameter)
                    result.append(first)
                    splits.append(height)
                    cut = second
            result.append(cut)
        return result

    monkeypatch.setattr(face_sections, "surface_curves", split_at_crossings)
    _assert_match(_compare(blade, (0, 0, 1), spacing=0.3), least=1.0)
    assert len(set(splits)) >= 5    # the case was made


@pytest.mark.parametrize("direction", [(0, 0, 1), (0, 1, 0), (0.3, -0.5, 0.8)])
def test_faces_covering_part_of_their_surface_are_cut_on_their_piece(App, Part, direction):
    """The trimmed blade's faces cover 2/3 of their surfaces' span: the plane is intersected
    with their pieces (OCC walks less), and the sections match the Boolean."""
    blade = _two_face_blade(App, Part)
    cutter = FaceCutter(blade, np.asarray(direction, dtype=float))
    splines = [d for d in cutter.faces if type(d.face.Surface).__name__ == "BSplineSurface"]
    assert len(splines) == 2
    for data in splines:
        assert data.cut_surface.bounds() == pytest.approx(data.face.ParameterRange, abs=1e-12)
        assert data.face.Surface.bounds() != pytest.approx(data.face.ParameterRange, abs=1e-3)
    _assert_match(_compare(blade, direction, spacing=0.3), least=1.0)


def test_planar_b_spline_sides_are_cut_as_their_planes():
    """A loft's flat sides are B-spline surfaces: OCC's surface intersection walked them
    (a coarse stack across an oblique prism's sides took 0.39 s, 0.09 s along its ends).
    Cut as the planes they are, every layer goes face by face and matches the Boolean."""
    prism = samples.oblique_prism()
    assert sum(type(f.Surface).__name__ == "BSplineSurface" for f in prism.Faces) == 4
    cutter = FaceCutter(prism, np.array([0.0, 1.0, 0.0]))
    assert [type(data.cut_surface).__name__ for data in cutter.faces].count("Plane") == 6
    for direction in ((0.0, 1.0, 0.0), (-0.978, -0.0714, 0.196), (0.3, -0.5, 0.8)):
        _assert_match(_compare(prism, direction, spacing=0.9), least=1.0)


def _notched_loft(App, Part):
    """An elliptic loft of closed, non-periodic B-spline profiles with a notch cut along
    +X: its side's section is one closed curve, part of it (the notch) outside the face."""
    def profile(z: float, a: float, b: float):
        points = [App.Vector(a * math.cos(t), b * math.sin(t), z)
                  for t in np.linspace(0.0, 2.0 * math.pi, 12, endpoint=False)]
        curve = Part.BSplineCurve()
        curve.interpolate(points + [points[0]], PeriodicFlag=False)
        return Part.Wire(curve.toShape())

    loft = Part.makeLoft([profile(0.0, 10.0, 6.0), profile(10.0, 8.0, 5.0)], True, False)
    return loft.cut(Part.makeBox(4, 2, 10, App.Vector(7, -1, 0))).Solids[0]


@pytest.mark.parametrize("shift", [4, 8, 12])
def test_a_piece_across_a_closed_curves_start_is_told_inside_or_out_on_the_curve(
        App, Part, monkeypatch, shift):
    """A closed curve's last piece runs past the end of a non-periodic parametrisation
    (`plane_curves.curve_spans`): whether it lies in the face is read at its middle taken
    back one turn (`span_middle`), not at a point OCC extrapolates off the curve. Read
    there, the fan hub's piece in its blade's notch was kept: 22 of its layers went to the
    Boolean. Here the section curves start beside the notch, as the hub's did."""
    import freecad_conformal.geometry.face_sections as face_sections

    solid = _notched_loft(App, Part)
    fitted = face_sections.surface_curves

    def started_beside_the_notch(surface, parameter_range, plane, n, height):
        curves = fitted(surface, parameter_range, plane, n, height)
        moved = []
        for curve in curves or []:
            if not isinstance(curve, Part.BSplineCurve) or curve.isPeriodic():
                moved.append(curve)
                continue
            points = curve.discretize(200)[:-1]
            start = (int(np.argmax([p.x for p in points])) + shift) % len(points)
            points = points[start:] + points[:start]
            refit = Part.BSplineCurve()
            refit.interpolate(points + [points[0]], PeriodicFlag=False)
            moved.append(refit)
        return moved if curves is not None else curves

    monkeypatch.setattr(face_sections, "surface_curves", started_beside_the_notch)
    cutter = FaceCutter(solid, (0, 0, 1))
    for height in (2.5, 5.0, 7.5):
        faces = cutter.section_faces(height)
        assert faces is not None, height
        plane = Part.makePlane(40, 40, App.Vector(-20, -20, height))
        exact = sum(f.Area for f in solid.common(plane).Faces)
        assert sum(f.face.Area for f in faces) == pytest.approx(exact, rel=AREA_REL)


def test_a_curvy_boundary_is_read_in_uv_as_closely_as_its_stencil_needs(App, Part):
    """Whether a point lies in a face is read from a polygon of its (u, v) boundary, and a
    point the polygon may place wrongly must have a neighbour in the stencil that disagrees
    (then OCC decides). A plate's wavy hole is one long B-spline edge: evenly spaced points
    cut across its crests, and the middles of short chords across them (a section's piece
    between two crossings, as on the coil spring's cut face) were read on the wrong side."""
    from freecad_conformal.geometry.uv_domain import FaceDomain

    def radius(t: float) -> float:
        return 5.0 + 1.5 * math.cos(8.0 * t)

    points = [App.Vector(radius(t) * math.cos(t), radius(t) * math.sin(t), 0.0)
              for t in np.linspace(0.0, 2.0 * math.pi, 240, endpoint=False)]
    curve = Part.BSplineCurve()
    curve.interpolate(points, PeriodicFlag=True)
    hole = Part.Face(Part.Wire(curve.toShape()))
    plate = Part.Face(Part.makePolygon([App.Vector(x, y, 0.0) for x, y in
                                        ((-15, -15), (15, -15), (15, 15), (-15, 15), (-15, -15))]))
    face = plate.cut(hole).Faces[0]
    assert len(face.Wires) == 2
    domain = FaceDomain(face)
    wrong = []
    step = curve.period() / 2000.0
    for t in np.linspace(curve.FirstParameter, curve.LastParameter, 400, endpoint=False):
        a, b = curve.value(float(t)), curve.value(float(t) + 4.0 * step)
        middle = App.Vector(0.5 * (a.x + b.x), 0.5 * (a.y + b.y), 0.0)
        if domain.contains(middle) != face.isInside(middle, 1e-7, True):
            wrong.append(float(t))
    assert not wrong


@pytest.mark.parametrize("angle, height, where", [
    (67.0, 45.0, "u"),      # a fillet's cylinder: 1.17 rad across, 45 mm long
    (300.0, 0.5, "v"),      # a thread-like strip: 5.2 rad around, 0.5 mm wide
])
def test_a_narrow_faces_points_near_its_boundary_are_told_by_the_polygon(
        App, Part, angle, height, where):
    """The polygon's stencil and deflection are shares of a face's shorter parameter range
    (`uv_domain.domain_scale`): shares of the longer one made the stencil wider than the
    points' distance across a narrow face, and OCC classified them (483 of the bottle's
    points cut along X, 0.49 s). Points 0.6 % of the narrow range inside and outside each
    side are decided without OCC, as OCC decides them."""
    from freecad_conformal.geometry.uv_domain import FaceDomain

    face = Part.makeCylinder(30.0, height, App.Vector(0, 0, 0), App.Vector(0, 0, 1), angle).Faces[0]
    u0, u1, v0, v1 = face.ParameterRange
    surface = face.Surface
    if where == "u":
        shift = 0.006 * (u1 - u0)
        uv = [(u, 0.5 * (v0 + v1)) for u in (u0 - shift, u0 + shift, u1 - shift, u1 + shift)]
    else:
        shift = 0.006 * (v1 - v0)
        uv = [(0.5 * (u0 + u1), v) for v in (v0 - shift, v0 + shift, v1 - shift, v1 + shift)]
    points = [surface.value(u, v) for u, v in uv]
    expected = [face.isInside(point, 1e-7, True) for point in points]
    assert expected == [False, True, True, False]
    domain = FaceDomain(face)

    def occ(point):
        raise AssertionError(f"OCC was asked about {point}")

    domain._classified = occ
    assert [domain.contains(point) for point in points] == expected


def test_a_face_of_straight_edges_is_its_corners_in_uv(App, Part):
    """A boundary of straight edges is exact with its corners alone (`uv_domain.STRAIGHT_2D`):
    48 points an edge cost a gear's 400 flat flanks 1.6 s of its plan choice. An L with a
    square hole (one wire reversed against the other): the polygon holds one point a corner,
    and it tells points 0.05 mm either side of every edge as OCC does, without OCC."""
    from freecad_conformal.geometry.uv_domain import FaceDomain

    def polygon(corners):
        return Part.makePolygon([App.Vector(x, y, 0.0) for x, y in corners + corners[:1]])

    outline = [(0, 0), (30, 0), (30, 10), (10, 10), (10, 30), (0, 30)]
    hole = [(3, 3), (7, 3), (7, 7), (3, 7)]
    face = Part.Face(polygon(outline)).cut(Part.Face(polygon(hole))).Faces[0]
    assert len(face.Wires) == 2 and face.Area == pytest.approx(30 * 10 + 10 * 20 - 16)
    domain = FaceDomain(face)

    def occ(point):
        raise AssertionError(f"OCC was asked about {point}")

    domain._classified = occ
    domain.prepare()
    rings = [domain._polygon.exterior, *domain._polygon.interiors]
    assert sorted(len(ring.coords) - 1 for ring in rings) == [4, 6]
    for ring in (outline, hole):
        for (x0, y0), (x1, y1) in zip(ring, ring[1:] + ring[:1]):
            middle = App.Vector((x0 + x1) / 2, (y0 + y1) / 2, 0.0)
            across = App.Vector(y1 - y0, x0 - x1, 0.0).normalize() * 0.05
            for point in (middle + across, middle - across):
                assert domain.contains(point) == face.isInside(point, 1e-7, True), point
