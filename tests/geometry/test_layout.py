"""Separate solids laid out on the platform, each standing on the base of its root."""
from __future__ import annotations

import math

import numpy as np
import pytest

from freecad_conformal.geometry.sections import extent_along
from freecad_conformal.decomposition.decompose import decompose
from freecad_conformal.jobs.plan import single_plan
from freecad_conformal.decomposition.layout import lay_out

UP = np.array([0.0, 0.0, 1.0])
GAP = 6.0


def footprints_apart(plan, gap: float) -> bool:
    boxes = {}
    for sub in plan.subparts:
        box = sub.shape.BoundBox
        old = boxes.get(sub.solid_index, (math.inf, -math.inf, math.inf, -math.inf))
        boxes[sub.solid_index] = (min(old[0], box.XMin), max(old[1], box.XMax),
                                  min(old[2], box.YMin), max(old[3], box.YMax))
    items = list(boxes.values())
    return all(a[1] + gap <= b[0] + 1e-9 or b[1] + gap <= a[0] + 1e-9
               or a[3] + gap <= b[2] + 1e-9 or b[3] + gap <= a[2] + 1e-9
               for i, a in enumerate(items) for b in items[i + 1:])


def check_standing(plan, platform: float) -> None:
    for sub in plan.subparts:
        if sub.parent is None:
            np.testing.assert_allclose(sub.build_direction, UP, atol=1e-12)
            assert extent_along(sub.shape, UP)[0] == pytest.approx(platform, abs=1e-7)
        _axis, angle = sub.rotation_axis, sub.rotation_angle
        assert angle == pytest.approx(math.acos(np.clip(sub.build_direction @ UP, -1, 1)), abs=1e-9)


def test_a_part_of_one_solid_built_along_z_from_the_platform_stays_as_placed(App, Part):
    plan = single_plan(Part.makeBox(10, 10, 10, App.Vector(3, 4, 0)))
    assert lay_out(plan, GAP) is plan


@pytest.mark.parametrize("z", [5.0, -149.0])
def test_a_part_modelled_above_or_below_the_platform_is_set_down_on_it(App, Part, z):
    """Built as modelled, a box at z = 5 had its first layer 5 mm in the air, and CrankArm
    (modelled at z = -149) was refused by a 3-axis machine whose Z starts at the bed. The
    part moves in Z only, onto z = 0, and the note says by how much."""
    box = Part.makeBox(10, 10, 10, App.Vector(3, 4, z))
    laid = lay_out(single_plan(box), GAP)
    check_standing(laid, 0.0)
    moved = laid.subparts[0].shape.BoundBox
    assert (moved.XMin, moved.YMin) == pytest.approx((3.0, 4.0), abs=1e-9)
    assert laid.notes == [f"solid 1 laid out on the platform: moved by (+0.000, +0.000, "
                          f"{-z:+.3f}) mm; its G-code is in that frame"]


def test_a_solid_hovering_over_another_is_set_down_beside_it(App, Part):
    """A ring around a pin (CrankArm's arm around its pin) hovers: it is lowered onto the
    platform and moved along +X clear of the pin; the pin keeps its place."""
    pin = Part.makeCylinder(3, 40, App.Vector(0, 0, 0))
    ring = Part.makeCylinder(10, 5, App.Vector(0, 0, 15)).cut(Part.makeCylinder(4, 5, App.Vector(0, 0, 15)))
    plan = single_plan(Part.Compound([pin, ring]))
    laid = lay_out(plan, GAP)
    check_standing(laid, 0.0)
    assert laid.subparts[0] is plan.subparts[0]
    moved = laid.subparts[1].shape
    assert moved.Volume == pytest.approx(ring.Volume, rel=1e-12)
    assert moved.BoundBox.XMin == pytest.approx(3.0 + GAP)
    assert footprints_apart(laid, GAP)
    assert any("solid 2 laid out" in note for note in laid.notes)
    assert not any("solid 1 laid out" in note for note in laid.notes)


def test_solids_side_by_side_at_different_heights_come_down_where_they_are(App, Part):
    """Two boxes modelled 30 mm apart, one 20 mm up: each is set down on the platform below
    where it was (the higher one was set beside the other with the tool's gap)."""
    low = Part.makeBox(10, 10, 10, App.Vector(0, 0, 0))
    high = Part.makeBox(10, 10, 10, App.Vector(40, 0, 20))
    laid = lay_out(single_plan(Part.Compound([low, high])), GAP)
    check_standing(laid, 0.0)
    for sub, box in zip(laid.subparts, (low, high)):
        moved = sub.shape.BoundBox
        assert (moved.XMin, moved.YMin) == pytest.approx((box.BoundBox.XMin, 0.0), abs=1e-9)
    assert laid.notes == ["solid 2 laid out on the platform: moved by (+0.000, +0.000, "
                          "-20.000) mm; its G-code is in that frame"]


def test_a_turned_root_stands_up_with_its_children_turned_alike(App, Part):
    """An L-block planned from −X: the whole solid turns so −X points up; the child's
    direction turns with it, and the angle between the two directions stays."""
    from freecad_conformal.geometry import samples

    shape = samples.l_block()
    plan = decompose(shape, root_direction=(-1.0, 0.0, 0.0), check_collisions=False)
    laid = lay_out(plan, GAP)
    check_standing(laid, 0.0)
    for before, after in zip(plan.subparts, laid.subparts):
        assert after.volume == before.volume
        assert after.shape.Volume == pytest.approx(before.shape.Volume, rel=1e-12)
        root_before = plan.subparts[0].build_direction
        assert after.build_direction @ UP == pytest.approx(before.build_direction @ root_before, abs=1e-12)
        if before.base_face is not None:
            # The base stays under its sub-part: the face lies on the moved shape's boundary.
            assert after.shape.distToShape(after.base_face)[0] < 1e-7
    assert laid.support_area == pytest.approx(plan.support_area, abs=1e-9)
    assert laid.axes[0].nodes[0].point is not plan.axes[0].nodes[0].point


def test_the_plan_builds_every_solid_from_the_platform(App, Part):
    """Through the plan command's pipeline: the ring's first layer is laid on the platform,
    not 15 mm above it."""
    from freecad_conformal.jobs.plan import PlanOptions, machine_plan, run_job

    pin = Part.makeCylinder(3, 12, App.Vector(0, 0, 0))
    ring = Part.makeCylinder(10, 2, App.Vector(0, 0, 5)).cut(Part.makeCylinder(4, 2, App.Vector(0, 0, 5)))
    options = PlanOptions()
    placed, plan = machine_plan(Part.Compound([pin, ring]), options)
    result = run_job(placed, plan, options, part="pin and ring")
    for sub in plan.subparts:
        tips = np.vstack([path.points for path in result.assembly.paths if path.subpart == sub.index])
        assert tips[:, 2].min() == pytest.approx(options.layers.thickness, abs=1e-9), sub.name


def test_a_part_modelled_below_the_bed_is_built_up_from_it(App, Part):
    """Through the plan command's pipeline on a 3-axis machine, whose Z travel starts at the
    bed: a cylinder modelled at z = -30..-18 (a part centred on another CAD system's origin)
    was refused ("Z = -29.8 mm ... outside the limits [0, 300]"); its layers now start one
    layer above the bed and end at its height."""
    from freecad_conformal.jobs.plan import PlanOptions, machine_plan, run_job

    options = PlanOptions(machine="three_axis", decompose=False)
    placed, plan = machine_plan(Part.makeCylinder(5, 12, App.Vector(20, 20, -30)), options)
    result = run_job(placed, plan, options, part="sunk cylinder")
    tips = np.vstack([path.points for path in result.assembly.paths])
    assert tips[:, 2].min() == pytest.approx(options.layers.thickness, abs=1e-9)
    assert tips[:, 2].max() == pytest.approx(12.0, abs=1e-9)


def test_solids_set_side_by_side_past_the_travel_are_moved_back_over_the_platform(App, Part):
    """A pin near the X limit with a ring hovering around it: set beside the pin the ring
    would end past x = 300 (CrankArm's arm reached 355); the arrangement is moved over the
    platform's centre instead, and the notes say so."""
    from freecad_conformal.jobs.plan import PlanOptions, machine_plan

    pin = Part.makeCylinder(3, 40, App.Vector(270, 0, 0))
    ring = Part.makeCylinder(10, 5, App.Vector(270, 0, 15)).cut(
        Part.makeCylinder(4, 5, App.Vector(270, 0, 15)))
    _, plan = machine_plan(Part.Compound([pin, ring]), PlanOptions(decompose=False))
    boxes = [sub.shape.BoundBox for sub in plan.subparts]
    low, high = min(b.XMin for b in boxes), max(b.XMax for b in boxes)
    assert -300.0 <= low and high <= 300.0
    assert abs(0.5 * (low + high)) < 1e-6               # over the trunnion's pivot
    assert any("laid out on the platform" in note for note in plan.notes)
    assert any("moved by" in note and "reached outside the machine's X/Y travel" in note
               for note in plan.notes)


def test_a_solid_lands_in_one_place_whether_or_not_it_was_meshed(App, Part):
    """`BoundBox` is read from a triangulation when the shape has one: the layout turned a
    solid the decomposition had meshed about another centre than the same solid fresh (the
    connecting rod's landed 1 mm apart). Its exact extents give one place."""
    from freecad_conformal.decomposition.layout import lay_out
    from freecad_conformal.jobs.plan import single_plan

    sections = [Part.Wire(Part.Ellipse(App.Vector(0, 0, z), a, 3.0).toShape())
                for z, a in ((0.0, 6.0), (15.0, 4.0), (30.0, 7.0))]
    solid = Part.makeLoft(sections, True, False)
    fresh = solid.BoundBox
    meshed = solid.copy()
    meshed.tessellate(0.05)
    corners = [np.array([b.XMin, b.YMin, b.ZMin, b.XMax, b.YMax, b.ZMax]) for b in (fresh, meshed.BoundBox)]
    assert np.abs(corners[0] - corners[1]).max() > 1.0     # the premise: 3.4 mm apart here
    placed = [lay_out(single_plan(shape, (1.0, 0.0, 0.0)), 5.0).subparts[0].shape
              for shape in (solid, meshed)]
    centres = [np.array(tuple(shape.CenterOfMass)) for shape in placed]
    assert np.allclose(centres[0], centres[1], atol=1e-6)


def test_a_plan_whose_tool_would_swing_past_the_travel_is_moved_over_the_pivot(App, Part):
    """A post and a tall rib built sideways (+X) beside it, off the table's pivot, inside
    the head machine's +-150 mm as laid out: the tilted head's retracts from the rib need
    Y = -170 mm, which the post refused after the layers and paths were made (CrankArm:
    23 s). The plan is moved over the pivot first, and then it is posted."""
    from freecad_conformal.decomposition.subparts import BuildPlan, SubPart
    from freecad_conformal.errors import KinematicsError
    from freecad_conformal.jobs.plan import PlanOptions, _within_travel, run_job
    from freecad_conformal.post.machine import load_machine

    machine = load_machine("head_a_table_c")
    post = Part.makeBox(26, 20, 72, App.Vector(50, -10, 0))
    rib = Part.makeBox(11, 41, 154, App.Vector(64, -77, 0))
    laid = BuildPlan([SubPart(0, post, np.array([0.0, 0.0, 1.0])),
                      SubPart(1, rib, np.array([1.0, 0.0, 0.0]), parent=0)], order=[0, 1])
    boxes = [sub.shape.BoundBox for sub in laid.subparts]
    assert all(-150 < v < 150 for b in boxes for v in (b.XMin, b.XMax, b.YMin, b.YMax))
    options = PlanOptions(machine="head_a_table_c")
    with pytest.raises(KinematicsError, match="outside the limits"):
        run_job(Part.makeCompound([post, rib]), laid, options, part="rib")
    moved = _within_travel(laid, machine)
    assert any("drove an axis past the machine's travel" in note for note in moved.notes)
    result = run_job(Part.makeCompound([s.shape for s in moved.subparts]), moved, options,
                     part="rib")
    assert sorted(s.index for s in result.subparts if s.layers > 0) == [0, 1]


@pytest.mark.slow
def test_a_solid_blocked_within_itself_keeps_the_cuts_it_can_build_beside_another(App, Part):
    """Beside a box, the post's low arm, built sideways into its foot, blocked the order of
    all the sub-parts: both solids were built whole (167.3 mm² of overhang). The post's own
    check undoes that one cut, and its other cuts stay (87.6 mm², as alone)."""
    from freecad_conformal.jobs.plan import PlanOptions, choose_plan, check_options
    from tests.geometry.test_decompose import _post_with_arms

    post = _post_with_arms(App, Part, low_arm=True)
    box = Part.makeBox(10, 10, 10, App.Vector(40, 0, 0))
    options = PlanOptions()
    both = Part.makeCompound([post, box])
    plan = choose_plan(both, options, check_options(both, options)).plan
    alone = decompose(post, root_direction=(0, 0, 1))
    assert not any(note.startswith("no decomposition could be built") for note in plan.notes)
    assert any("built with P1 instead" in note for note in plan.notes)
    assert len(plan.subparts) == len(alone.subparts) + 1
    assert plan.support_area == pytest.approx(alone.support_area, rel=1e-6)
    assert plan.support_area < 0.6 * plan.support_area_single_direction
    whole_box = [s for s in plan.subparts if s.solid_index == 1]
    assert len(whole_box) == 1 and whole_box[0].volume == pytest.approx(1000.0, rel=1e-9)


def test_a_solid_is_set_where_its_sub_parts_are_built_away_from_the_others(App, Part):
    """The tool stands on the side a sub-part is built towards: a ring whose lug is built
    along -X is set on the -X side of the pin, so that the tool building the lug points away
    from the pin (set on +X, CrankArm's arm built its end along -X into its pin: no order)."""
    import dataclasses

    pin = Part.makeCylinder(3, 40, App.Vector(0, 0, 0))
    ring = Part.makeCylinder(10, 5, App.Vector(0, 0, 15)).cut(Part.makeCylinder(4, 5, App.Vector(0, 0, 15)))
    lug = Part.makeBox(6, 4, 5, App.Vector(-16, -2, 15))
    plan = single_plan(Part.Compound([pin, ring]))
    root = plan.subparts[1]
    child = dataclasses.replace(root, index=2, shape=lug, build_direction=np.array([-1.0, 0.0, 0.0]),
                                parent=root.index, volume=lug.Volume, name="P3", rule="branch")
    plan = dataclasses.replace(plan, subparts=plan.subparts + [child], order=[0, 1, 2])
    laid = lay_out(plan, GAP)
    pin_centre = np.array(tuple(laid.subparts[0].shape.BoundBox.Center))
    ring_centre = np.array(tuple(laid.subparts[1].shape.BoundBox.Center))
    towards_pin = pin_centre - ring_centre
    assert np.linalg.norm(towards_pin[:2]) > 10.0
    assert towards_pin @ laid.subparts[2].build_direction < 0.0
    assert footprints_apart(laid, GAP)
