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
