"""Decomposition acceptance on parametric parts (METHODS sections 3 and 4)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from freecad_conformal.geometry import samples
from freecad_conformal.decomposition.decompose import decompose


def directions(plan):
    return [tuple(np.round(s.build_direction, 6) + 0.0) for s in plan.ordered()]


def test_l_block_splits_once_and_builds_the_arm_horizontally():
    plan = decompose(samples.l_block())
    assert len(plan.subparts) == 2
    assert directions(plan) == [(0, 0, 1), (1, 0, 0)]
    first, second = plan.ordered()
    assert second.parent == first.index
    assert first.volume == pytest.approx(10 * 20 * 40)
    assert second.volume == pytest.approx(30 * 20 * 10)
    assert plan.support_area == pytest.approx(0.0, abs=1e-6)
    assert math.degrees(second.rotation_angle) == pytest.approx(90.0)
    np.testing.assert_allclose(second.rotation_axis, [0, -1, 0], atol=1e-12)


def test_t_builds_the_stem_then_arms_in_plus_and_minus_x():
    plan = decompose(samples.t_block())
    assert len(plan.subparts) == 3
    assert directions(plan)[0] == (0, 0, 1)
    assert sorted(directions(plan)[1:]) == [(-1, 0, 0), (1, 0, 0)]
    root = plan.ordered()[0]
    assert all(s.parent == root.index for s in plan.ordered()[1:])
    assert sum(s.volume for s in plan.subparts) == pytest.approx(samples.t_block().Volume)
    assert plan.support_area == pytest.approx(0.0, abs=1e-6)


def test_hinge_gives_five_subparts_in_the_published_turns():
    plan = decompose(samples.hinge())
    ordered = plan.ordered()
    assert len(ordered) == 5
    assert directions(plan)[0] == (0, 0, 1)
    assert directions(plan)[1:3] == [(0, 1, 0), (0, 1, 0)]
    assert directions(plan)[3:] == [(0, 0, -1), (0, 0, -1)]
    for sub in ordered[1:3]:      # turned 90° about X
        np.testing.assert_allclose(sub.rotation_axis, [1, 0, 0], atol=1e-12)
        assert math.degrees(sub.rotation_angle) == pytest.approx(90.0)
    for sub in ordered[3:]:       # turned 180° about Y, each on its knuckle
        np.testing.assert_allclose(sub.rotation_axis, [0, 1, 0], atol=1e-12)
        assert math.degrees(sub.rotation_angle) == pytest.approx(180.0)
        assert plan.subparts[sub.parent].build_direction[1] == pytest.approx(1.0)
    assert plan.support_area == pytest.approx(0.0, abs=1e-6)


def test_inclined_rod_needs_no_split_when_followed_in_its_direction():
    plan = decompose(samples.inclined_rod(tilt_deg=30.0))
    assert len(plan.subparts) == 1
    axis = plan.axes[0]
    tilt = np.array([math.sin(math.radians(30)), 0, math.cos(math.radians(30))])
    assert any(abs(float(b.direction @ tilt)) > math.cos(math.radians(2)) for b in axis.branches)


def test_published_axis_turns_only_along_the_axes():
    plan = decompose(samples.l_block(), method="published")
    assert len(plan.subparts) == 2
    for branch in plan.axes[0].branches:
        assert np.count_nonzero(np.abs(branch.direction) > 1e-9) == 1


def test_plan_json_names_every_subpart_and_the_saving():
    plan = decompose(samples.l_block(), check_collisions=False)
    data = plan.to_dict()
    assert data["format"] == "conformal.plan/1"
    assert [s["name"] for s in data["subparts"]] == ["P1", "P2"]
    assert data["support_area_saved"] == pytest.approx(plan.support_area_saved)
    assert data["axes"][0]["format"] == "conformal.axis/1"


def _stool(legs: int):
    """A 40 × 40 × 4 mm seat on `legs` round legs (∅4 mm, 20 mm long) under it."""
    from freecad_conformal.freecad_env import import_freecad

    App, Part = import_freecad()
    seat = Part.makeBox(40, 40, 4, App.Vector(0, 0, 20))
    spots = [(8, 8), (32, 8), (20, 32)][:legs]
    for x, y in spots:
        seat = seat.fuse(Part.makeCylinder(2, 20, App.Vector(x, y, 0)))
    return seat.removeSplitter()


def test_stool_turned_over_is_seat_then_each_leg_on_it():
    stool = _stool(3)
    plan = decompose(stool, root_direction=(0, 0, -1))
    seat, *legs = plan.ordered()
    assert len(legs) == 3
    assert seat.volume == pytest.approx(40 * 40 * 4)
    for leg in legs:
        assert leg.parent == seat.index and leg.rule == "member"
        np.testing.assert_allclose(leg.build_direction, [0, 0, -1], atol=1e-9)
        assert leg.volume == pytest.approx(math.pi * 4 * 20)
        assert leg.base_face.Area == pytest.approx(math.pi * 4)
    assert plan.support_area == pytest.approx(0.0, abs=1e-6)


def test_one_column_on_a_base_stays_whole():
    plan = decompose(_stool(1), root_direction=(0, 0, -1))
    assert len(plan.subparts) == 1


@pytest.mark.parametrize("name", ["t_block", "hinge"])
def test_regions_are_computed_only_for_planes_whose_cuts_are_tried(name, monkeypatch):
    """A plane's interior regions cost a section Boolean each: the search computes them
    only for the planes it goes on to split exactly."""
    import freecad_conformal.geometry.splitting_faces as splitting
    import freecad_conformal.decomposition.planner as module

    computed: list[list] = []
    tried: set[int] = set()
    plane_regions, try_cut = splitting.plane_regions, module.try_cut

    def counted_regions(solid, plane):
        regions = plane_regions(solid, plane)
        computed.append(regions)
        return regions

    def counted_cut(piece, candidate, angle, **options):
        tried.add(id(candidate))
        return try_cut(piece, candidate, angle, **options)

    monkeypatch.setattr(splitting, "plane_regions", counted_regions)
    monkeypatch.setattr(module, "try_cut", counted_cut)
    plan = decompose(samples.SAMPLES[name]())
    assert len(plan.subparts) > 1 and computed
    assert all(any(id(region) in tried for region in regions) for regions in computed if regions)


@pytest.mark.parametrize("make, direction", [
    (samples.t_block, (0.0, 0.0, -1.0)),       # a T turned over stands on its bar
    (samples.l_block, (0.0, 0.0, -1.0)),       # an upside-down L stands on its arm
])
def test_a_part_support_free_when_turned_whole_is_not_split(make, direction):
    """A planar slicer would simply turn these over; splitting them costs material and time."""
    plan = decompose(make(), root_direction="auto")
    assert len(plan.subparts) == 1
    assert np.allclose(plan.subparts[0].build_direction, direction)
    assert plan.subparts[0].overhang_area == pytest.approx(0.0, abs=1e-3)
    assert any("whole solid is support-free" in note for note in plan.notes)


def test_a_u_channel_with_inward_lips_builds_whole_on_its_side(App, Part):
    """It fails as placed ("no collision-free build order") but prints support-free whole
    standing on one of its ends or sides."""
    V = App.Vector
    channel = Part.makeBox(40, 30, 20)
    channel = channel.cut(Part.makeBox(40, 20, 12, V(0, 5, 4)))       # the U's inside
    channel = channel.cut(Part.makeBox(40, 10, 4, V(0, 10, 16)))      # the gap between the lips
    plan = decompose(channel, root_direction="auto")
    assert len(plan.subparts) == 1
    assert plan.subparts[0].overhang_area == pytest.approx(0.0, abs=1e-3)


@pytest.mark.parametrize("rests_on_a_corner", [True, False])
def test_a_part_modelled_turned_is_planned_as_well_as_upright(App, Part, monkeypatch,
                                                              rests_on_a_corner):
    """An L-bracket with a bore through its base and one through its upright needs support
    for one bore whichever way it stands. Modelled turned 33° off every axis, its roots
    were the six axes of the file's frame: four sub-parts with 244.5 mm² left. Standing
    it on its base (a place-on-face direction) leaves the upright's bore alone, as upright.
    As placed it rests on a corner, so it is stood on the best direction it stands in; were
    it standing (a base under it), the further roots would find its base."""
    import freecad_conformal.decomposition.decompose as module

    if not rests_on_a_corner:
        monkeypatch.setattr(module, "stands", lambda shape, d: True)
    V = App.Vector
    bracket = Part.makeBox(40, 30, 5).fuse(Part.makeBox(5, 30, 40))
    bracket = bracket.cut(Part.makeCylinder(4, 5, V(0, 15, 25), V(1, 0, 0)))
    bracket = bracket.cut(Part.makeCylinder(5, 5, V(25, 15, 0), V(0, 0, 1))).removeSplitter()
    turned = bracket.copy()
    turned.rotate(V(20, 15, 20), V(1, 1, 0), 33)
    turned.translate(V(120, -80, 30))
    upright = decompose(bracket, root_direction="auto", with_axes=False)
    plan = decompose(turned, root_direction="auto", with_axes=False)
    assert len(upright.subparts) == len(plan.subparts) == 1
    assert upright.support_area > 1.0       # a bore's top: no direction is support-free
    assert plan.support_area == pytest.approx(upright.support_area, rel=1e-3)
    why = "as placed it would rest on 0.0 mm²" if rests_on_a_corner else "than the other roots"
    assert any(why in note for note in plan.notes)


def test_a_part_that_overhangs_alike_every_way_is_not_turned_for_the_measures_noise(Part):
    """A hollow sphere overhangs 920.15 mm² whichever way it is built; the mesh read
    919.04 along Z and 918.60 along Y, and the sphere was turned onto its side "with less
    overhang than as placed". A turn must save more than the measure's noise."""
    from freecad_conformal.decomposition.decompose import TURN_SAVING
    from freecad_conformal.geometry.overhang import DEFAULT_OVERHANG_ANGLE, overhang_area

    hollow = Part.makeSphere(20.0).cut(Part.makeSphere(10.0))
    along = {d: overhang_area(hollow, np.array(d), DEFAULT_OVERHANG_ANGLE)
             for d in ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0))}
    assert 0.0 < along[(0.0, 0.0, 1.0)] - along[(0.0, 1.0, 0.0)] < TURN_SAVING  # the noise
    plan = decompose(hollow, root_direction="auto", with_axes=False)
    assert not any("root built along" in note for note in plan.notes), plan.notes
    assert [tuple(s.build_direction) for s in plan.subparts] == [(0.0, 0.0, 1.0)]
    # The best single direction it reports (and the search builds whole) is as placed too.
    assert tuple(plan.single_direction) == (0.0, 0.0, 1.0)
    assert plan.support_area_saved == 0.0


def test_a_part_is_never_stood_on_a_corner_to_avoid_support():
    """The jack has no overhang balanced on a corner (every face 35° off vertical), but a
    corner gives no adhesion: its root must stand on a flat face."""
    from freecad_conformal.geometry.overhang import MIN_BASE_AREA, base_area

    plan = decompose(samples.jack(), root_direction="auto")
    root = next(s for s in plan.subparts if s.parent is None)
    assert base_area(root.shape, root.build_direction) >= MIN_BASE_AREA


@pytest.mark.parametrize("x, kept", [(0.0, True), (-9.5, False)])
def test_a_cut_never_leaves_a_sliver_sub_part(App, Part, x, kept):
    """A cap overhanging a column on the -X side, cut across the cap at `x`: flush with the
    column the child is 10 mm thick along its direction (-X) and the cut stands; 0.5 mm from
    the cap's end it would be a sliver (CrankArm's staircase of area-jump cuts made 16 such
    sub-parts, 0.002-0.85 mm thick, most too thin to hold a layer) and the cut is refused."""
    from freecad_conformal.decomposition.planner import (
        MIN_SUBPART_THICKNESS, Piece, try_cut)
    from freecad_conformal.geometry.splitting_faces import SplitCandidate

    V = App.Vector
    part = Part.makeBox(10, 10, 20).fuse(Part.makeBox(30, 10, 5, V(-10, 0, 20))).removeSplitter()
    region = Part.Face(Part.makePolygon([V(x, 0, 20), V(x, 10, 20), V(x, 10, 25), V(x, 0, 25),
                                         V(x, 0, 20)]))
    candidate = SplitCandidate(np.array([x, 0.0, 22.5]), np.array([1.0, 0.0, 0.0]), region,
                               "area-jump")
    root = Piece(part.Solids[0], np.array([0.0, 0.0, 1.0]))
    result = try_cut(root, candidate, math.radians(45))
    assert (result is not None) == kept
    if kept:
        _, _, children = result
        assert len(children) == 1
        assert np.allclose(children[0].direction, [-1.0, 0.0, 0.0])
        box = children[0].shape.BoundBox
        assert box.XLength == pytest.approx(10.0)
        assert box.XLength > MIN_SUBPART_THICKNESS


@pytest.mark.parametrize("name", ["l_block", "hinge"])
def test_a_plan_without_axes_has_the_same_sub_parts_and_skips_the_axis(name, monkeypatch):
    """The job's plan (`with_axes=False`) is the same split as the Analysis' plan, without
    the centroidal axis the search did not need: each solid's axis is otherwise computed
    at the end for the preview alone (2.5 s of the bottle's 9 s plan choice)."""
    from freecad_conformal.geometry import centroidal_axis

    calls = []
    original = centroidal_axis.centroidal_axis

    def counted(*args, **kwargs):
        calls.append(kwargs.get("start_direction"))
        return original(*args, **kwargs)

    monkeypatch.setattr(centroidal_axis, "centroidal_axis", counted)
    shape = getattr(samples, name)()
    full = decompose(shape, root_direction="auto")
    with_axes = len(calls)
    calls.clear()
    lean = decompose(shape, root_direction="auto", with_axes=False)
    assert len(full.axes) == 1 and lean.axes == []
    assert len(calls) < with_axes
    assert directions(lean) == directions(full)
    assert [s.volume for s in lean.ordered()] == pytest.approx([s.volume for s in full.ordered()])
    assert lean.support_area == pytest.approx(full.support_area)


def test_a_cuts_saving_reads_each_face_once_per_direction(Part, monkeypatch):
    """Candidate planes share normals: the saving estimate reads a curved face's mesh once
    per direction (the fan's +Z plan read them 3,200 times, 1.3 s), and gives what reading
    it every time gives."""
    from freecad_conformal.decomposition.cuts import SavingEstimate
    from freecad_conformal.geometry import surface_mesh
    from freecad_conformal.geometry.overhang import DEFAULT_OVERHANG_ANGLE, overhang_report
    from freecad_conformal.geometry.splitting_faces import SplitCandidate

    rod = Part.makeCylinder(5.0, 20.0, Part.Vertex(0, 0, 0).Point, Part.Vertex(1, 0, 0).Point)
    report = overhang_report(rod, (0.0, 0.0, 1.0), DEFAULT_OVERHANG_ANGLE, on_bed=False)
    planes = [SplitCandidate(np.array([x, 0.0, -1.0]), np.array(normal), None, "area-jump")
              for x in (2.0, 4.0, 6.0) for normal in ((1.0, 0.0, 0.0), (0.0, 0.0, 1.0))]
    fresh = [SavingEstimate(rod, DEFAULT_OVERHANG_ANGLE, report).saving(p) for p in planes]
    read = []
    below = surface_mesh.FacePart.below
    monkeypatch.setattr(surface_mesh.FacePart, "below",
                        lambda part, d, t: read.append(1) or below(part, d, t))
    estimate = SavingEstimate(rod, DEFAULT_OVERHANG_ANGLE, report)
    assert [estimate.saving(p) for p in planes] == fresh
    # Built along +X the lower quarter of the lateral face no longer overhangs: all saved.
    assert fresh[0] == pytest.approx(report.area) and fresh[1] == 0.0
    assert len(read) == 2     # the lateral face, along +X and +Z


@pytest.mark.parametrize("fraction, pieces", [(None, 1), (0.005, 2)])
def test_a_cut_saving_a_sliver_of_the_overhang_is_not_made(App, Part, monkeypatch,
                                                            fraction, pieces):
    """A 400 mm long wall whose cap overhangs by 0.5 mm along its length (200 mm², too thin
    to cut off) and a 2 x 1 mm lip on its other side: cutting the lip off saves 2 of 202 mm²,
    under the 2 % a cut must save (the fan's chain of slivers), so the part stays whole; the
    same cut is made where the rule asks less (the cut itself is possible)."""
    from freecad_conformal.decomposition import planner

    if fraction is not None:
        monkeypatch.setattr(planner, "MIN_SAVING_FRACTION", fraction)
    V = App.Vector
    part = (Part.makeBox(10, 400, 20).fuse(Part.makeBox(10.5, 400, 5, V(0, 0, 20)))
            .fuse(Part.makeBox(2, 1, 5, V(-2, 0, 20)))).removeSplitter().Solids[0]
    plan = planner.Planner(part, 0, math.radians(45), "true-direction", None, 24)
    found, _ = plan.pieces(np.array([0.0, 0.0, 1.0]))
    assert len(found) == pieces
    assert sum(p.overhang for p in found) == pytest.approx(202.0 if pieces == 1 else 200.0,
                                                           abs=1e-3)
    if pieces == 2:
        lip = min(found, key=lambda p: p.shape.Volume)
        assert lip.shape.Volume == pytest.approx(10.0)
        assert np.allclose(lip.direction, [-1.0, 0.0, 0.0])


def _rack(arms: int, lean_deg: float):
    """A post (r 5, 30 mm) with `arms` round arms (r 4, 35 mm) leaving its top, leaning
    `lean_deg` from the vertical, evenly around it: a Y, a coat rack."""
    from freecad_conformal.freecad_env import import_freecad

    App, Part = import_freecad()
    shape = Part.makeCylinder(5.0, 30.0)
    lean = math.radians(lean_deg)
    for k in range(arms):
        turn = 2 * math.pi * k / arms
        direction = App.Vector(math.sin(lean) * math.cos(turn), math.sin(lean) * math.sin(turn),
                               math.cos(lean))
        shape = shape.fuse(Part.makeCylinder(4.0, 35.0, App.Vector(0, 0, 28), direction))
    return shape.removeSplitter().Solids[0]


@pytest.mark.parametrize("arms", [2, 4])
def test_round_arms_leaning_off_a_post_are_each_built_along_their_own_axis(arms):
    """No planar face marks where the arms leave the post, and area-jump planes (square to
    X, Y, Z) cut an arm 20-30° above the horizontal through the post: before branch planes
    the post as placed kept its arms' whole overhang (a 4-arm rack 719.7 mm², a Y 276.9)."""
    rack = _rack(arms, 70.0 if arms == 4 else 60.0)
    plan = decompose(rack, root_direction=(0, 0, 1))
    post, *rest = plan.ordered()
    np.testing.assert_allclose(post.build_direction, [0, 0, 1], atol=1e-12)
    branches = [s for s in rest if s.rule == "branch"]
    assert len(branches) == arms
    # and no sliver off an arm's tip first (an area jump along X did that when tried before
    # the branch planes)
    assert len(rest) == arms
    lean = math.radians(70.0 if arms == 4 else 60.0)
    for branch in branches:
        assert branch.parent == post.index
        assert branch.build_direction[2] == pytest.approx(math.cos(lean), abs=1e-9)
        assert branch.volume > 0.8 * math.pi * 16 * 35 / 2
    assert plan.support_area < 0.05 * overhang_of(rack)
    assert sum(s.volume for s in plan.subparts) == pytest.approx(rack.Volume, rel=1e-6)


def _knob(levers: int, tilt_deg: float = 0.0):
    """A round knob (r 12, 15 mm, domed) with `levers` square bars (6 x 5 mm, reaching
    x = 33) leaving its side at mid-height, evenly around it, each turned `tilt_deg` about
    its own axis (its sides then lie square to no axis of the part)."""
    from freecad_conformal.freecad_env import import_freecad

    App, Part = import_freecad()
    V = App.Vector
    shape = Part.makeCylinder(12, 15).fuse(Part.makeSphere(12, V(0, 0, 15), V(0, 0, 1), 0, 90))
    for k in range(levers):
        bar = Part.makeBox(25, 6, 5, V(8, -3, -2.5))
        bar.rotate(V(0, 0, 0), V(1, 0, 0), tilt_deg)
        bar.translate(V(0, 0, 10.5))
        bar.rotate(V(0, 0, 0), V(0, 0, 1), 360.0 * k / levers)
        shape = shape.fuse(bar)
    return shape.removeSplitter().Solids[0]


@pytest.mark.parametrize("levers, tilt", [(1, 0.0), (2, 0.0), (1, 30.0)])
def test_square_levers_leaving_a_round_body_are_each_built_along_their_own_axis(levers, tilt):
    """A lever leaves the knob on no planar splitting face (its sides meet the cylinder),
    no area jump marks it (the body's section along the lever shrinks to nothing where the
    lever goes on) and no round member carries it: the knob kept its levers' whole
    undersides as overhang (126.8 mm² each) until planes square to the one direction all
    of a lever's planar sides run along were tried."""
    knob = _knob(levers, tilt)
    plan = decompose(knob, root_direction=(0, 0, 1))
    body, *rest = plan.ordered()
    np.testing.assert_allclose(body.build_direction, [0, 0, 1], atol=1e-12)
    assert [s.rule for s in rest] == ["branch"] * levers
    axes = {(round(math.cos(2 * math.pi * k / levers), 6) + 0.0,
             round(math.sin(2 * math.pi * k / levers), 6) + 0.0, 0.0) for k in range(levers)}
    assert {tuple(np.round(s.build_direction, 6) + 0.0) for s in rest} == axes
    for lever in rest:
        assert lever.parent == body.index
        # cut just beyond the body: nearly all of the 21 mm the lever stands out
        assert lever.volume == pytest.approx(30 * (33 - 12 - 0.2), rel=1e-3)
    # what is left: the stubs' undersides between the body and the cut, 2 mm² each
    assert plan.support_area < 2.5 * levers
    assert overhang_of(knob) > 120 * levers
    assert sum(s.volume for s in plan.subparts) == pytest.approx(knob.Volume, rel=1e-6)


def overhang_of(shape) -> float:
    from freecad_conformal.geometry.overhang import overhang_area

    return overhang_area(shape, np.array([0.0, 0.0, 1.0]), math.radians(45.0))


def _post_with_arms(App, Part, low_arm: bool):
    """A column on a wide foot with a collar and an arm high up; with `low_arm`, a second
    arm just above the foot, which a tool building it sideways would drive into the foot."""
    V = App.Vector
    post = Part.makeCylinder(5, 40).fuse([
        Part.makeCylinder(15, 3), Part.makeTorus(5, 2.5, V(0, 0, 36)),
        Part.makeCylinder(2.5, 20, V(0, 0, 25), V(0, 1, 0))])
    if low_arm:
        post = post.fuse(Part.makeCylinder(2, 16, V(0, 0, 7), V(0, -1, 0)))
    return post.removeSplitter().Solids[0]


@pytest.mark.slow
def test_a_cut_the_tool_cannot_build_is_undone_and_the_others_are_kept(App, Part):
    """The low arm's cut would build it sideways into the foot: that sub-part is fused back
    into the column and the other cuts stay. Before, that one collision left no plan at all
    (`plan` then built the part whole: 167.3 mm² of overhang against 87.6). The high arm
    built along +Y would meet the collar above it, which its own cut takes off first:
    checking each trial cut against the whole piece it is cut from (not only the faces it
    divides) kept two sub-parts of the four here."""
    part = _post_with_arms(App, Part, low_arm=True)
    free = decompose(part, root_direction=(0, 0, 1), check_collisions=False)
    plan = decompose(part, root_direction=(0, 0, 1))
    assert len(plan.subparts) == len(free.subparts) - 1
    # named as first planned: the low arm, built along -Y
    low_arm = max((s for s in free.subparts if s.build_direction[1] < -0.5),
                  key=lambda s: s.volume)
    assert any(note.startswith(f"{low_arm.name} (along") and "built with P1 instead" in note
               for note in plan.notes)
    assert plan.support_reason == (f"the cut of {low_arm.name} undone, as the tool would hit "
                                   "the part building it")
    assert sum(s.volume for s in plan.subparts) == pytest.approx(part.Volume, rel=1e-6)
    column = plan.subparts[plan.order[0]]
    assert column.parent is None and column.shape.isValid()
    # the low arm is in the column again: its section 7 mm up reaches 16 mm out along -Y
    assert column.shape.BoundBox.YMin == pytest.approx(-16.0, abs=1e-6)
    # the kept cuts still save most of the overhang
    assert free.support_area < plan.support_area < 0.6 * plan.support_area_single_direction
    high_arm = max(plan.subparts, key=lambda s: s.volume if s.parent is not None else 0.0)
    np.testing.assert_allclose(high_arm.build_direction, [0, 1, 0], atol=1e-9)


def _coil(App, Part, turns: float = 1.5, pitch: float = 6.0, radius: float = 12.0,
          wire: float = 1.5):
    """A round wire coiled along a helix, standing on a disc."""
    helix = Part.makeHelix(pitch, turns * pitch, radius)
    edge = helix.Edges[0]
    start, along = edge.valueAt(edge.FirstParameter), edge.tangentAt(edge.FirstParameter)
    profile = Part.Wire(Part.Circle(start, along, wire).toShape())
    coil = Part.Wire(helix.Edges).makePipeShell([profile], True, True)
    disc = Part.makeCylinder(radius + 2.0, 2.0, App.Vector(0, 0, -2.0))
    return coil.fuse(disc).removeSplitter().Solids[0]


def test_a_cut_the_tool_would_build_into_its_own_wire_is_not_made(App, Part, monkeypatch):
    """Cut off, a coil's wire is built along the cut's normal inside the coil, where the tool
    meets the rest of the wire: such a cut is rejected on the mesh, before its exact split
    (a coil of five turns spent 7 s of its 18 s decomposition making one, then no order
    could build it and `plan` built the part whole anyway). The notes and the support
    reason say why the overhang stays."""
    from freecad_conformal.decomposition import planner
    from freecad_conformal.decomposition.build_order import BlockedOrder, build_order
    from freecad_conformal.decomposition.decompose import TOOL_BLOCKED_CUTS

    coil = _coil(App, Part)
    made: list[int] = []
    real = planner.try_cut
    monkeypatch.setattr(planner, "try_cut", lambda *args, **kw: made.append(1) or real(*args, **kw))
    plan = decompose(coil, root_direction=(0, 0, 1))
    assert not made
    assert len(plan.subparts) == 1
    assert plan.support_area == pytest.approx(plan.support_area_single_direction, rel=1e-9)
    assert plan.support_reason == TOOL_BLOCKED_CUTS
    assert any("not made: building what lies beyond, the tool would hit the piece" in note
               for note in plan.notes)
    # Unchecked, the cuts are made, and then no order builds them: the check agrees.
    free = decompose(coil, root_direction=(0, 0, 1), check_collisions=False)
    assert made and len(free.subparts) > 1
    with pytest.raises(BlockedOrder):
        build_order(free.subparts, tool="fdm_0p4")


def test_a_plan_whose_only_cut_cannot_be_built_still_says_so(App, Part, monkeypatch):
    """Undoing the one cut leaves the solid whole, which is not a decomposition: the error
    names the collision of the plan as made (the caller then builds the part whole)."""
    from freecad_conformal.decomposition import decompose as module
    from freecad_conformal.errors import PlanError

    fused: list[str] = []
    real = module._fused
    monkeypatch.setattr(module, "_fused", lambda parent, child: fused.append(child.rule)
                        or real(parent, child))
    V = App.Vector
    # a pawn: a turned body under a collar and a ball; the one cut takes the collar's side
    outline = Part.makePolygon([V(0, 0, 0), V(12, 0, 0), V(12, 0, 4), V(6, 0, 8), V(5, 0, 22),
                                V(0, 0, 22), V(0, 0, 0)])
    body = Part.Solid(Part.Shell(Part.Face(outline).revolve(V(), V(0, 0, 1), 360).Faces))
    pawn = body.fuse([Part.makeTorus(5, 2.5, V(0, 0, 20)), Part.makeSphere(6, V(0, 0, 26))])
    pawn = pawn.removeSplitter().Solids[0]
    with pytest.raises(PlanError, match=r"for 2 sub-parts: P2 \(along .*\) would hit P1"):
        decompose(pawn, root_direction=(0, 0, 1))
    assert len(fused) == 1


@pytest.mark.slow
@pytest.mark.parametrize("rests_on_an_edge", [True, False])
def test_a_further_root_whose_split_saves_most_is_planned(App, Part, monkeypatch,
                                                          rests_on_an_edge):
    """A round-bar L on a square foot, modelled turned 40° about Y. Planned as placed it
    kept 57.4 mm² of overhang in four sub-parts; built whole on its foot it would keep
    81.5 mm², more than that, so the foot's root was never planned, though its split leaves
    2.4 mm² in two. Further roots were then weighed against the whole solid as placed; as
    placed it rests on an edge of its foot (2.8 mm² of first layer), so it is now stood on
    the best direction it stands in, its foot's; were it standing, the further roots would
    find its foot."""
    import freecad_conformal.decomposition.decompose as module

    if not rests_on_an_edge:
        monkeypatch.setattr(module, "stands", lambda shape, d: True)
    V = App.Vector
    hook = Part.makeCylinder(3, 40).fuse([Part.makeCylinder(3, 20, V(0, 0, 40), V(1, 0, 0)),
                                          Part.makeSphere(3, V(0, 0, 40)),
                                          Part.makeBox(14, 14, 3, V(-7, -7, -3))])
    hook = hook.removeSplitter().Solids[0]
    hook.rotate(V(), V(0, 1, 0), 40)
    plan = decompose(hook, root_direction="auto", check_collisions=False)
    foot = np.array([math.sin(math.radians(40)), 0.0, math.cos(math.radians(40))])
    root = next(s for s in plan.subparts if s.parent is None)
    np.testing.assert_allclose(root.build_direction, foot, atol=1e-9)
    assert plan.support_area < 5.0 and len(plan.subparts) == 2
    assert plan.support_area_single_direction > 80.0
    why = "as placed it would rest on 2.8 mm²" if rests_on_an_edge else "than the other roots"
    assert any(why in note for note in plan.notes)


@pytest.mark.slow
def test_a_thorough_root_search_plans_the_part_turned_over_too(parts_dir):
    """CrankArm's arm lies flat as modelled: split as placed it keeps 2,477 mm² of overhang,
    stood on its side (its best axis whole) 1,170; turned over, with as much overhang whole
    as placed, its split keeps 647. The quick search stops at its side; the thorough one
    plans from there too and keeps that."""
    from freecad_conformal.geometry.solids import load_shape

    arm = max(load_shape(parts_dir / "CrankArm.brep").Solids, key=lambda s: s.Volume)
    quick = decompose(arm, root_direction="auto", with_axes=False)
    thorough = decompose(arm, root_direction="auto", with_axes=False, thorough=True)
    left = [sum(sub.overhang_area for sub in plan.subparts) for plan in (quick, thorough)]
    assert left[1] < 0.7 * left[0]
    assert any("root built along (-0, -0, -1)" in note for note in thorough.notes)
    assert not any("-1)" in note and "root built along" in note for note in quick.notes)


def _seat_down_stool_and_a_block(App, Part):
    """A 3-legged stool standing on its seat (legs up: support-free as placed) and, beside
    it, a 10 mm block: two solids."""
    stool = Part.makeBox(40, 40, 4)
    for x, y in [(8, 8), (32, 8), (20, 32)]:
        stool = stool.fuse(Part.makeCylinder(2, 20, App.Vector(x, y, 4)))
    return Part.makeCompound([stool.removeSplitter(), Part.makeBox(10, 10, 10, App.Vector(60, 0, 0))])


def test_a_support_free_solid_of_several_is_one_sub_part_when_asked(App, Part):
    """METHODS section 4 makes the legs sub-parts of their own (`decompose` as published),
    built the same way as the seat: more sub-parts, no overhang saved. The plan job asks for
    a solid that is support-free as placed to stay whole, as its search builds one solid."""
    part = _seat_down_stool_and_a_block(App, Part)
    published = decompose(part, root_direction="auto")
    assert sorted(s.rule for s in published.subparts) == ["member"] * 3 + ["root"] * 2
    whole = decompose(part, root_direction="auto", whole_when_support_free=True)
    assert len(whole.subparts) == 2
    assert sorted(s.volume for s in whole.subparts) == pytest.approx(
        [1000.0, 40 * 40 * 4 + 3 * math.pi * 4 * 20])
    assert whole.support_area == pytest.approx(0.0, abs=1e-6)
    assert any("built whole as placed" in note for note in whole.notes)


def test_the_plan_job_builds_a_support_free_solid_of_several_whole(App, Part):
    from freecad_conformal.jobs.plan import PlanOptions, check_options, choose_plan

    part = _seat_down_stool_and_a_block(App, Part)
    options = PlanOptions()
    plan = choose_plan(part, options, check_options(part, options)).plan
    assert len(plan.subparts) == 2
    assert all(s.rule == "root" for s in plan.subparts)


def test_each_solid_of_several_is_searched_as_one_alone(App, Part):
    """Two plates modelled standing on their 60 x 3 mm edges are support-free as placed;
    one alone is laid flat by the search (15 layers, 18 min, against 200 layers standing).
    Both are now laid flat too (they stood: 400 layers, 70 min instead of 36)."""
    from freecad_conformal.jobs.plan import PlanOptions, check_options, choose_plan

    part = Part.makeCompound([Part.makeBox(60, 3, 40),
                              Part.makeBox(60, 3, 40, App.Vector(0, 20, 0))])
    options = PlanOptions()
    plan = choose_plan(part, options, check_options(part, options)).plan
    assert len(plan.subparts) == 2
    for sub in plan.subparts:
        assert np.allclose(sub.build_direction, (0.0, 0.0, 1.0))
        assert sub.shape.BoundBox.ZLength == pytest.approx(3.0)
        assert sub.shape.Volume == pytest.approx(60 * 3 * 40)
    chosen = [note for note in plan.notes if "chosen among" in note]
    assert [note.split(":")[0] for note in chosen] == ["solid 1", "solid 2"]


def test_a_solid_to_decompose_beside_one_searched_keeps_its_decomposition(App, Part):
    """The jack needs support in every orientation: it is decomposed as alone (its seven
    sub-parts), while the plate modelled standing beside it is laid flat by its own search
    (it stood on its edge: 200 layers instead of 15)."""
    from freecad_conformal.geometry import samples
    from freecad_conformal.jobs.plan import PlanOptions, check_options, choose_plan

    plate = Part.makeBox(60, 3, 40, App.Vector(51, 0, 0))
    part = Part.makeCompound([samples.jack(), plate])
    options = PlanOptions()
    plan = choose_plan(part, options, check_options(part, options)).plan
    jack = [sub for sub in plan.subparts if sub.solid_index == 0]
    (flat,) = [sub for sub in plan.subparts if sub.solid_index == 1]
    assert len(jack) > 2
    assert flat.shape.BoundBox.ZLength == pytest.approx(3.0)
    assert np.allclose(flat.build_direction, (0.0, 0.0, 1.0))
    assert plan.support_area == pytest.approx(0.0, abs=1.0)
    assert [note.split(":")[0] for note in plan.notes if "chosen among" in note] == ["solid 2"]


def _spool(holes: int):
    """A tube (r 15 / 12, 60 mm) with a flange (r 30, 5 mm) at each end, each with `holes`
    bolt holes (r 3) on a 23 mm circle: the upper flange overhangs the tube all round."""
    from freecad_conformal.freecad_env import import_freecad

    App, Part = import_freecad()
    V = App.Vector
    flange = Part.makeCylinder(30, 5).cut(Part.makeCylinder(12, 5))
    for k in range(holes):
        turn = 2 * math.pi * k / holes
        flange = flange.cut(Part.makeCylinder(3, 5, V(23 * math.cos(turn), 23 * math.sin(turn), 0)))
    tube = Part.makeCylinder(15, 60).cut(Part.makeCylinder(12, 60))
    return tube.fuse([flange, flange.translated(V(0, 0, 55))]).removeSplitter().Solids[0]


@pytest.mark.parametrize("holes", [0, 6])
def test_a_flange_over_a_shaft_is_cut_off_by_planes_along_the_shaft_just_clear_of_it(holes):
    """A spool as placed: the upper flange's underside (2120 mm²) overhangs the tube all
    round. Square to the tube it makes no area jump, no planar face splits it off and no
    member leaves the tube sideways: area jumps cut two of its sides off where the tube
    begins along one axis only, and left 1015.0 mm² (1052.7 with the holes). Eight planes
    along the tube, 0.2 mm clear of it, cut the flange's sides off, each built outwards,
    leaving the corners of an octagon round the tube over it (58.7 mm²)."""
    from freecad_conformal.decomposition.cuts import BRANCH_CLEARANCE, FLANGE_SIDES

    spool = _spool(holes)
    plan = decompose(spool, root_direction=(0, 0, 1))
    tube, *sides = plan.ordered()
    np.testing.assert_allclose(tube.build_direction, [0, 0, 1], atol=1e-12)
    assert [s.rule for s in sides] == ["flange"] * FLANGE_SIDES
    turns = [2 * math.pi * k / FLANGE_SIDES for k in range(FLANGE_SIDES)]
    assert sorted(directions(plan)[1:]) == sorted(
        (round(math.cos(t), 6) + 0.0, round(math.sin(t), 6) + 0.0, 0.0) for t in turns)
    reach = 15.0 + BRANCH_CLEARANCE
    corners = FLANGE_SIDES * reach ** 2 * math.tan(math.pi / FLANGE_SIDES) - math.pi * 15.0 ** 2
    assert overhang_of(tube.shape) == pytest.approx(corners, rel=0.01)
    assert plan.support_area < corners + 4 * 50.0       # the bolt holes' upper halves
    assert sum(s.volume for s in plan.subparts) == pytest.approx(spool.Volume, rel=1e-6)


def test_fusing_a_cut_back_leaves_the_other_pieces_as_they_were():
    """Pieces of one split share faces and edges; OCC's fuse with `removeSplitter` on two of
    them changed those shared ones in place: on a disc cut by three planes the first piece
    then read 5,440 mm³ instead of 1,251 and a neighbour -3,854 instead of 335, and a
    bobbin's merge-back (no collision-free order for its collar) gave up on a piece of
    negative volume. The fuse works on copies."""
    from freecad_conformal.decomposition.decompose import _fused
    from freecad_conformal.decomposition.planner import Piece
    from freecad_conformal.freecad_env import import_freecad
    from freecad_conformal.geometry.splitting_faces import plane_through, split_solid

    _, Part = import_freecad()
    disc = Part.makeCylinder(20, 5)
    planes = [((8, 0, 0), (1, 0, 0)), ((0, 8, 0), (0, 1, 0)), ((-8, 0, 0), (-1, 0, 0))]
    regions = [disc.common(plane_through(np.array(p, float), np.array(n, float),
                                         disc.BoundBox)).Faces[0] for p, n in planes]
    pieces = split_solid(disc, regions)
    before = [p.Volume for p in pieces]
    assert len(pieces) == 6 and min(before) > 0
    for i, j in [(0, 1), (1, 0), (2, 3), (0, 5)]:
        fused = _fused(Piece(pieces[i], np.array([0.0, 0.0, 1.0])),
                       Piece(pieces[j], np.array([0.0, 0.0, 1.0])))
        np.testing.assert_allclose([p.Volume for p in pieces], before, rtol=1e-9)
        if fused is not None:
            assert fused.shape.Volume == pytest.approx(before[i] + before[j], rel=1e-6)
    assert sum(before) == pytest.approx(disc.Volume, rel=1e-9)


def test_a_flange_the_tool_cannot_build_past_another_is_not_cut():
    """A bobbin: a hub (r 8, 30 mm) with cheeks (r 25 x 3) at both ends and a collar
    (r 14 x 4) between them. The tool building the upper cheek's or the collar's sides
    outwards would meet the cheek below, which stays on the bed: the sixteen flange cuts
    made were all undone when no order could build them (9.6 s of the plan instead of
    2.8), and `decompose` as placed ended in "no collision-free build order". They are
    not made, and a note says why."""
    from freecad_conformal.freecad_env import import_freecad

    App, Part = import_freecad()
    V = App.Vector
    cheek = Part.makeCylinder(25, 3)
    bobbin = Part.makeCylinder(8, 30).fuse(
        [cheek, cheek.translated(V(0, 0, 27)), Part.makeCylinder(14, 4, V(0, 0, 13))])
    bobbin = bobbin.cut(Part.makeCylinder(4, 30)).removeSplitter().Solids[0]
    plan = decompose(bobbin, root_direction=(0, 0, 1))
    assert all(s.rule != "flange" for s in plan.subparts)
    assert any("not made: building what lies beyond, the tool would hit the piece" in note
               for note in plan.notes)
    assert sum(s.volume for s in plan.subparts) == pytest.approx(bobbin.Volume, rel=1e-6)
