"""Toolpath assembly from a BuildPlan: order, tool axes, material, safe moves, collisions."""
from __future__ import annotations

import numpy as np
import pytest

from freecad_conformal.errors import PlanError
from freecad_conformal.geometry import samples
from freecad_conformal.paths.approach import SAFE_MARGIN, bounding_sphere, check_clearance, transition
from freecad_conformal.paths.assemble import PathSettings, assemble
from freecad_conformal.paths.fill2d import FillSettings
from freecad_conformal.layers.model import LayerSettings
from freecad_conformal.layers.plan import plan_layers
from freecad_conformal.decomposition.subparts import BuildPlan, SubPart
from freecad_conformal.process.library import ToolLibrary
from freecad_conformal.toolpath import KINDS


@pytest.fixture(scope="module")
def envelope():
    return ToolLibrary.load(user_dir=None).get("fdm_0p4").envelope


@pytest.fixture(scope="module")
def split_bracket(App, Part):
    """The sample bracket split at the arm's root: base + column (+Z), then the arm (+X)."""
    shape = samples.overhang_bracket()
    arm_box = Part.makeBox(30, 30, 10, App.Vector(10, 0, 40))
    arm = shape.common(arm_box).Solids[0]
    root = shape.cut(arm_box).Solids[0]
    return shape, BuildPlan([SubPart(0, root, np.array([0.0, 0, 1]), volume=root.Volume),
                             SubPart(1, arm, np.array([1.0, 0, 0]), parent=0, volume=arm.Volume)],
                            order=[0, 1])


@pytest.fixture(scope="module")
def assembled(split_bracket, envelope):
    _, plan = split_bracket
    settings = LayerSettings(thickness=0.5)
    layers = {s.index: plan_layers(s, settings) for s in plan.subparts}
    solid = PathSettings(fill=FillSettings(bead_width=0.5, density=1.0), top_layers=0, bottom_layers=0)
    return plan, layers, assemble(plan, layers, solid, envelope, part="bracket")


def test_sub_parts_in_plan_order_with_their_tool_axes(assembled):
    plan, layers, result = assembled
    order = [p.subpart for p in result.paths]
    assert order == sorted(order) and set(order) == {0, 1}
    for path in result.paths:
        np.testing.assert_allclose(path.axis, plan.subparts[path.subpart].build_direction)
    tp = result.toolpath
    deposit = tp.kind == KINDS.index("deposit")
    starts = tp.segment_starts
    for segment in np.flatnonzero(deposit):
        axes = tp.axes[starts[segment]:starts[segment + 1]]
        assert np.allclose(axes, axes[0])


def test_arm_layers_stack_along_x(assembled):
    _, layers, result = assembled
    arm = [p for p in result.paths if p.subpart == 1]
    xs = [p.points[:, 0] for p in arm]
    assert all(np.ptp(x) < 1e-9 for x in xs)             # each arm layer lies in an x = const plane
    assert min(x[0] for x in xs) == pytest.approx(10.5) and max(x[0] for x in xs) == pytest.approx(40.0)


def test_solid_fill_material_matches_the_part(split_bracket, assembled):
    """At 100 % fill, bead width × height × length equals the volume (connectors, corners
    and thin-wall gaps aside)."""
    shape, _ = split_bracket
    _, _, result = assembled
    material = result.toolpath.summary().material_volume
    assert material == pytest.approx(shape.Volume, rel=0.04)


def test_moves_between_sub_parts_clear_built_material(split_bracket, assembled, Part, App):
    plan, _, result = assembled
    assert result.moves_checked == 1
    root = plan.subparts[0].shape
    tp = result.toolpath
    travel = np.flatnonzero(tp.kind == KINDS.index("travel"))
    starts = tp.segment_starts
    first_arm = next(k for k, p in enumerate(result.paths) if p.subpart == 1)
    # the travel just before the arm's first deposit is the safe move: it turns the tool
    segment = [s for s in travel if not np.allclose(tp.axes[starts[s]:starts[s + 1]], [0, 0, 1])][0]
    points = tp.points[starts[segment]:starts[segment + 1] - 1]
    wire = Part.makePolygon([App.Vector(*p) for p in points])
    assert wire.distToShape(root)[0] >= SAFE_MARGIN - 1e-6
    assert first_arm > 0


def test_a_move_through_material_is_refused(App, Part, envelope):
    block = Part.makeBox(10, 10, 10)
    points = np.array([[-5.0, 5, 5], [0.0, 5, 5], [15.0, 5, 5], [20.0, 5, 5]])
    axes = np.tile([0.0, 0, 1], (4, 1))
    with pytest.raises(PlanError, match="tool tip passes 0.000 mm from built sub-part 0"):
        check_clearance(points, axes, [block], envelope, "move to sub-part 1", "sub-part 0")


def test_tool_body_is_checked_too(App, Part, envelope):
    """The tip stays clear above the block, but the body would sweep through a tower."""
    tower = Part.makeBox(4, 4, 60, App.Vector(8, -2, -10))
    points = np.array([[0.0, 0, 20], [10.0, -20, 20], [20.0, 0, 20], [30.0, 0, 20]])
    axes = np.tile([0.0, 1.0, 0.0], (4, 1))
    with pytest.raises(PlanError, match="tool body passes"):
        check_clearance(points, axes, [tower], envelope, "move", "sub-part 0")


def test_a_move_past_a_curved_face_is_judged_by_its_distance_not_its_box(App, Part):
    """Only segments and faces whose boxes come within the clearance are measured, each
    exactly: a tip crossing the corner of a sphere's box but well clear of the sphere
    passes, one skimming the sphere is refused with the gap OCC measures to the solid."""
    from freecad_conformal.process.tools import Envelope

    envelope = Envelope(tip_diameter=1.0, tip_length=3.0, body_diameter=0.5, body_length=5.0)
    ball = Part.makeSphere(10.0)
    need = 0.5 * envelope.tip_diameter
    corner = np.array([9.5, 9.5, -40.0])            # inside the box's corner, 3.4 mm out
    axes = np.tile([0.0, 0.0, 1.0], (3, 1))
    clear = np.array([corner, corner + [0, 0, 40], corner + [0, 0, 80]])
    check_clearance(clear, axes, [ball], envelope, "move", "sub-part 0")
    skim = clear - [2.26, 2.26, 0.0]                # 7.24 * sqrt 2 = 10.24: 0.24 mm out
    wire = Part.makePolygon([App.Vector(*p) for p in skim])
    gap = wire.distToShape(ball)[0]
    assert 0.0 < gap < need
    with pytest.raises(PlanError, match=f"tool tip passes {gap:.3f} mm"):
        check_clearance(skim, axes, [ball], envelope, "move", "sub-part 0")


def test_transition_goes_over_the_safe_sphere():
    centre, radius = np.zeros(3), 10.0
    points, axes = transition(np.array([0.0, 0, 10]), np.array([0.0, 0, 1]),
                              np.array([10.0, 0, 0]), np.array([1.0, 0, 0]), centre, radius)
    distances = np.linalg.norm(points[:-1] - centre, axis=1)
    assert distances.min() >= radius + SAFE_MARGIN - 1e-9
    np.testing.assert_allclose(points[-1], [10, 0, 0])
    np.testing.assert_allclose(axes[0], [0, 0, 1])
    np.testing.assert_allclose(axes[-1], [1, 0, 0])
    assert np.allclose(np.linalg.norm(axes, axis=1), 1.0)


def test_bounding_sphere(Part):
    centre, radius = bounding_sphere([Part.makeBox(2, 2, 1)])
    np.testing.assert_allclose(centre, [1, 1, 0.5])
    assert radius == pytest.approx(1.5)


@pytest.mark.slow
def test_small_layers_are_slowed_to_the_minimum_layer_time(envelope):
    jack_arm = samples.jack()
    plan = BuildPlan([SubPart(0, jack_arm, np.array([0.0, 0, 1]))], order=[0])
    layers = {0: plan_layers(plan.subparts[0], LayerSettings(thickness=1.0, tilt=False))}
    slow = assemble(plan, layers, PathSettings(min_layer_time=30.0), envelope)
    fast = assemble(plan, layers, PathSettings(min_layer_time=0.0), envelope)
    deposit = slow.toolpath.kind == KINDS.index("deposit")
    assert slow.toolpath.feed[deposit].min() < fast.toolpath.feed[deposit].min()
    assert slow.toolpath.feed[deposit].min() >= PathSettings().min_speed - 1e-9


def test_the_tool_axis_turns_the_way_the_tip_travels():
    """Leaving along −X and arriving along +Y just below the centre, the tip goes over the
    top of the safe sphere (the side way dips); the axis must go over the top with it, not
    turn sideways and lay the tool body across the part."""
    centre, radius = np.zeros(3), 15.0
    points, axes = transition(np.array([-10.0, 0.0, -1.0]), np.array([-1.0, 0.0, 0.0]),
                              np.array([0.0, 10.0, -1.0]), np.array([0.0, 1.0, 0.0]), centre, radius)
    arc, arc_axes = points[:-1], axes[:-1]
    assert arc[:, 2].max() > radius                                  # over the top
    radial = arc / np.linalg.norm(arc, axis=1)[:, None]
    assert np.einsum("ij,ij->i", radial, arc_axes).min() > 0.5        # body points away from the part
    np.testing.assert_allclose(axes[-1], [0.0, 1.0, 0.0])


def test_sub_parts_from_one_level_in_one_direction_are_laid_layer_by_layer(App, Part, envelope):
    """Two posts on the platform (the table's legs, solids side by side): each layer of both
    before the next, as the build order's collision check assumes; the cooling slowdown
    then sees the two posts' layer as one."""
    posts = [Part.makeBox(4, 4, 3, App.Vector(x, 0, 0)) for x in (0, 20)]
    plan = BuildPlan([SubPart(k, post, np.array([0.0, 0, 1]), volume=post.Volume, solid_index=k)
                      for k, post in enumerate(posts)], order=[0, 1])
    layers = {s.index: plan_layers(s, LayerSettings(thickness=0.5, tilt=False)) for s in plan.subparts}
    settings = PathSettings(fill=FillSettings(bead_width=0.5, density=1.0), min_layer_time=8.0)
    result = assemble(plan, layers, settings, envelope)
    heights = [float(path.points[0][2]) for path in result.paths]
    assert heights == sorted(heights)
    for k in range(6):
        level = [path.subpart for path in result.paths if path.layer == k]
        assert level == sorted(level) and set(level) == {0, 1}, k
    alone = assemble(BuildPlan([plan.subparts[0]], order=[0]), {0: layers[0]}, settings, envelope)
    deposit = result.toolpath.kind == KINDS.index("deposit")
    single = alone.toolpath.kind == KINDS.index("deposit")
    # One post alone is slowed to fill 8 s per layer; two together take less slowing.
    assert result.toolpath.feed[deposit].min() > alone.toolpath.feed[single].min()


def test_members_of_a_level_go_in_group_order_whatever_their_last_bit():
    """Layer tops of grouped sub-parts a rounding apart are one level, built in the group's
    order: the table's legs, cut from one solid, sit 1e-13 mm apart, and which of them was
    built first followed that bit (2.6 m more travel, 26 s, after a change of 1e-13 mm in
    where the part ends)."""
    from types import SimpleNamespace

    from freecad_conformal.paths.assemble import SAME_LEVEL, _levels

    up = np.array([0.0, 0.0, 1.0])

    def stack(offset: float) -> list:
        return [SimpleNamespace(top_point=np.array([0.0, 0.0, 0.2 * (k + 1) + offset]),
                                top_normal=up) for k in range(3)]

    below = -0.1 * SAME_LEVEL
    for offsets in ((0.0, below), (below, 0.0), (0.0, 1e-13), (1e-13, 0.0)):
        layers = [stack(offset) for offset in offsets]
        paths = [[[f"member {m} layer {k}"] for k in range(3)] for m in range(2)]
        assert _levels(paths, layers) == [[f"member 0 layer {k}", f"member 1 layer {k}"]
                                          for k in range(3)], offsets
