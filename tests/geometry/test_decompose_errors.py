"""Bad input to the decomposition gives clear errors; collisions are found and named."""
from __future__ import annotations

import math

import pytest

from freecad_conformal.errors import GeometryError, PlanError
from freecad_conformal.geometry import samples
from freecad_conformal.decomposition.build_order import build_order
from freecad_conformal.decomposition.decompose import decompose
from freecad_conformal.process.tools import Envelope


def test_shell_is_refused(Part):
    with pytest.raises(GeometryError, match="Shell"):
        decompose(Part.makeBox(1, 1, 1).Shells[0])


def test_empty_shape_is_refused(Part):
    with pytest.raises(GeometryError, match="empty"):
        decompose(Part.Shape())


def test_invalid_solid_is_refused(Part, App):
    box = Part.makeBox(10, 10, 10)
    broken = Part.Solid(Part.Shell(box.Faces[:5] + [box.Faces[0]]))
    with pytest.raises(GeometryError):
        decompose(broken)


def test_bad_angle_and_method_are_refused():
    with pytest.raises(PlanError, match="overhang angle"):
        decompose(samples.l_block(), overhang_angle=math.radians(95))
    with pytest.raises(PlanError, match="method"):
        decompose(samples.l_block(), method="medial")


def test_blocked_order_names_the_subparts():
    plan = decompose(samples.hinge(), check_collisions=False)
    # A body wider than the whole part: a lug built downwards (−Z) would sweep over the wall.
    huge = Envelope(tip_diameter=1.0, tip_length=1.0, body_diameter=500.0, body_length=500.0)
    with pytest.raises(PlanError, match="no collision-free build order") as caught:
        build_order(plan.subparts, tool=huge)
    lugs = [s.name for s in plan.subparts if s.build_direction[2] < -0.5]
    assert all(f"{name} (along" in str(caught.value) for name in lugs)
    assert "would hit P1" in str(caught.value)


def test_a_lone_sub_part_is_never_sampled(monkeypatch, Part):
    # Nothing is built before the only sub-part: meshing it for the check is waste (Pump_Nut
    # and every whole orientation paid 0.06-0.08 s for it); the hinge's pieces are sampled.
    from freecad_conformal.geometry import collision

    sampled = []
    real = collision.surface_points
    monkeypatch.setattr(collision, "surface_points",
                        lambda shape, spacing: sampled.append(shape) or real(shape, spacing))
    whole = decompose(Part.makeBox(20, 10, 5), check_collisions=False)
    assert len(whole.subparts) == 1
    assert build_order(whole.subparts, tool="fdm_0p4") == [0]
    assert sampled == []
    plan = decompose(samples.hinge(), check_collisions=False)
    huge = Envelope(tip_diameter=1.0, tip_length=1.0, body_diameter=500.0, body_length=500.0)
    with pytest.raises(PlanError):
        build_order(plan.subparts, tool=huge)
    assert len(sampled) >= 2
