"""What the code assumes of OpenCASCADE, pinned so an OCC upgrade that changes it is noticed
here rather than as a wrong section or split far away."""
from __future__ import annotations

import pytest


def test_local_tolerances_that_claim_occs_confusion_still_equal_it(Part):
    from freecad_conformal.decomposition import mesh_cut
    from freecad_conformal.geometry import splitting_faces
    from freecad_conformal.geometry.solids import occ_confusion

    confusion = Part.Precision.confusion()
    assert occ_confusion() == confusion
    # documented as "OCC's default confusion": on-face tests and the shape fixer's precision
    assert splitting_faces.ON_FACE == confusion
    assert splitting_faces.FIX_PRECISION == confusion
    assert mesh_cut.ON_PLANE == confusion


def test_our_point_tolerances_sit_between_rounding_and_occs_confusion(Part):
    from freecad_conformal import tolerances

    confusion = Part.Precision.confusion()
    assert 1e-15 < tolerances.COINCIDENT_POINTS < confusion
    assert 1e-15 < tolerances.ZERO_LENGTH < confusion
    assert tolerances.DEFAULT_CHORD_TOLERANCE > confusion   # polygons never finer than OCC


def test_a_plane_section_of_a_box_is_exact_to_occs_confusion(Part):
    """sections.py trusts OCC's planar common to be exact (area to 1e-9 relative)."""
    from freecad_conformal.geometry.sections import planar_sections

    box = Part.makeBox(10, 20, 30)
    section = planar_sections(box, heights=[7.5]).layers[0]
    assert section.area == pytest.approx(200.0, rel=1e-9)
