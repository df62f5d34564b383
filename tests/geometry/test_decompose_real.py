"""Decomposition of the real parts: what the plan reports as remaining overhang is exactly
what each sub-part has in its build direction, and the plan never does worse than the best
single direction when the root may turn ("auto")."""
from __future__ import annotations

import numpy as np
import pytest

from freecad_conformal.geometry.solids import load_shape
from freecad_conformal.planning.decompose import decompose
from freecad_conformal.planning.support import overhang_report

#: Overhang areas are compared to this (mm²): the plan and the check read the same faces.
AREA_TOLERANCE = 1e-6


def remaining(plan) -> list[float]:
    """Each sub-part's overhang recomputed from its shape, direction and base."""
    areas = []
    for sub in plan.subparts:
        bases = [sub.base_face] if sub.parent is not None else []
        report = overhang_report(sub.shape, sub.build_direction, plan.overhang_angle, bases,
                                 on_bed=sub.parent is None)
        areas.append(report.area)
    return areas


def check_reported_exactly(plan, shape) -> None:
    np.testing.assert_allclose([s.overhang_area for s in plan.subparts], remaining(plan),
                               atol=AREA_TOLERANCE)
    assert plan.support_area == pytest.approx(sum(remaining(plan)), abs=AREA_TOLERANCE)
    # Splits of B-spline faces (CrankArm) lose ~1e-5 of the volume to Boolean tolerances.
    assert sum(s.volume for s in plan.subparts) == pytest.approx(shape.Volume, rel=1e-4)
    assert sorted(plan.order) == list(range(len(plan.subparts)))
    for position, index in enumerate(plan.order):
        parent = plan.subparts[index].parent
        assert parent is None or plan.order.index(parent) < position


def test_table_turned_whole_leaves_only_the_fillets_at_the_bed(parts_dir):
    shape = load_shape(parts_dir / "MODERN_Table_1.brep")
    plan = decompose(shape, root_direction="auto")
    check_reported_exactly(plan, shape)
    assert plan.support_area <= plan.support_area_single_direction + AREA_TOLERANCE
    root = plan.ordered()[0]
    np.testing.assert_allclose(root.build_direction, [0, 0, -1], atol=1e-12)
    # What remains: the 1 mm edge round of the top, on the bed side once it is turned over.
    for sub in plan.subparts:
        for name in sub.overhang_faces:
            face = sub.shape.Faces[int(name[4:]) - 1]
            assert type(face.Surface).__name__ == "Cylinder"
            assert face.BoundBox.ZMin >= 59.0 - 1e-6


@pytest.mark.slow
def test_table_as_placed_reports_what_remains(parts_dir):
    shape = load_shape(parts_dir / "MODERN_Table_1.brep")
    plan = decompose(shape)
    check_reported_exactly(plan, shape)
    assert plan.ordered()[0].build_direction @ np.array([0, 0, 1.0]) == pytest.approx(1.0)


def test_screw_head_needs_no_support_as_placed(parts_dir):
    shape = load_shape(parts_dir / "screw.step")
    plan = decompose(shape)
    check_reported_exactly(plan, shape)
    assert plan.support_area == pytest.approx(0.0, abs=AREA_TOLERANCE)


@pytest.mark.slow
def test_crank_arm_plans_both_solids(parts_dir):
    shape = load_shape(parts_dir / "CrankArm.brep")
    plan = decompose(shape, root_direction="auto")
    check_reported_exactly(plan, shape)
    assert {s.solid_index for s in plan.subparts} == {0, 1}
    assert plan.support_area <= plan.support_area_single_direction + AREA_TOLERANCE
