"""Area-jump planes (METHODS section 4): the mesh profile the decomposition proposes planes
from agrees with the exact sections."""
from __future__ import annotations

import math

import numpy as np
import pytest

from freecad_conformal.geometry.area_jumps import MeshProfile, area_jump_planes


def test_mesh_profile_areas_of_a_stepped_cylinder(App, Part):
    # ∅20 mm for 10 mm, then ∅40 mm for 10 mm: the section is 100π then 400π mm².
    shape = Part.makeCylinder(10, 10).fuse(Part.makeCylinder(20, 10, App.Vector(0, 0, 10)))
    areas = MeshProfile(shape).areas(np.array([0.0, 0.0, 1.0]), np.array([2.5, 7.5, 12.5, 17.5]))
    np.testing.assert_allclose(areas, [100 * math.pi] * 2 + [400 * math.pi] * 2, rtol=5e-3)
    # At a level face's own height the section is the one just below it: the triangles
    # wholly below count whole, those lying in the plane not at all.
    levels = MeshProfile(shape).areas(np.array([0.0, 0.0, 1.0]), np.array([0.0, 10.0, 20.0]))
    np.testing.assert_allclose(levels, [0.0, 100 * math.pi, 400 * math.pi], rtol=5e-3, atol=1e-9)
    # Across the axis the section is a rectangle through the centre: 20·10 + 40·10 mm².
    across = MeshProfile(shape).areas(np.array([1.0, 0.0, 0.0]), np.array([0.0]))
    assert across[0] == pytest.approx(600.0, rel=5e-3)


@pytest.mark.slow
@pytest.mark.parts
def test_mesh_and_exact_profiles_find_the_same_jumps_on_the_crank_arm(parts_dir):
    from freecad_conformal.geometry.solids import load_shape

    arm = load_shape(parts_dir / "CrankArm.brep").Solids[1]
    up = np.array([0.0, 0.0, 1.0])
    exact = area_jump_planes(arm, up, limit=100)
    mesh = area_jump_planes(arm, up, limit=100, exact=False)
    key = lambda planes: sorted((tuple(np.round(n, 9)), round(float(p @ n), 6)) for _, p, n in planes)
    assert key(mesh) == key(exact)


@pytest.mark.parametrize("as_splines", [False, True], ids=["planes", "B-spline planes"])
def test_planes_lie_inside_the_part_and_on_the_face_where_the_area_jumps(App, Part, as_splines):
    """Along −X/−Y/−Z the planes were mirrored through the origin (a part spanning x 3..33
    got a plane at x = −12.75), and every plane sat on the sampling grid's midpoint, which
    can cut through the member the jump belongs to. Faces written as B-splines
    (`toNurbs`, as lofts and exporters write planes) are levels too: their planes sat at
    z = 29.75, 0.25 mm into the column under the cap."""
    import numpy as np

    from freecad_conformal.geometry.area_jumps import area_jump_planes

    V = App.Vector
    column = Part.makeBox(10, 10, 30, V(13, 10, 0))
    cap = Part.makeBox(30, 30, 5, V(3, 0, 30))
    part = column.fuse(cap).removeSplitter()
    if as_splines:
        part = part.toNurbs()
        assert {type(face.Surface).__name__ for face in part.Faces} == {"BSplineSurface"}
    box = part.BoundBox
    planes = area_jump_planes(part, np.array([1.0, 0.0, 0.0]))
    assert planes
    for _, point, axis in planes:
        assert box.XMin - 1e-9 <= point[0] <= box.XMax + 1e-9 or abs(axis[0]) < 0.5
        assert box.YMin - 1e-9 <= point[1] <= box.YMax + 1e-9 or abs(axis[1]) < 0.5
        assert box.ZMin - 1e-9 <= point[2] <= box.ZMax + 1e-9 or abs(axis[2]) < 0.5
    by_axis = {tuple(np.round(axis, 6)): point for _, point, axis in planes}
    assert by_axis[(0.0, 0.0, 1.0)][2] == 30.0            # the cap's underside, exactly
    assert by_axis[(0.0, -1.0, 0.0)][1] == 20.0           # the column's far side, not y = -20
