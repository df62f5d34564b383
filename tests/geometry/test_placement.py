"""Placing the part on the table so the machine reaches every sub-part (the hinge's lugs)."""
from __future__ import annotations

import numpy as np
import pytest

from freecad_conformal.errors import PlanError
from freecad_conformal.geometry import samples
from freecad_conformal.jobs.plan import PlanOptions, check_reach, machine_plan, run_job
from freecad_conformal.jobs.placement import reachable_plan, turn_up
from freecad_conformal.decomposition.subparts import BuildPlan, SubPart
from freecad_conformal.post.machine import load_machine


def test_a_placed_copy_is_meshed_at_its_originals_deflection(Part):
    """The plan's copy of the part, turned or not, meshes at the deflection the orientation
    scans used for the part: its own box, read from the mesh it carries, is tighter than the
    part's was before any mesh (a B-spline ball's: 50 -> 34.6 mm), and BRepMesh meshed the
    swept spring's copy again at the finer deflection (5.1 s of its plan choice)."""
    from freecad_conformal.geometry.surface_mesh import (RELATIVE_DEFLECTION, mesh_deflection,
                                                         surface_mesh)

    ball = Part.makeSphere(10.0).toNurbs().Solids[0]
    first = mesh_deflection(ball)
    surface_mesh(ball)
    assert RELATIVE_DEFLECTION * ball.BoundBox.DiagonalLength < 0.8 * first
    assert mesh_deflection(ball) == first
    for up in ((0.0, 0.0, 1.0), (1.0, 0.0, 0.0), (0.3, 0.4, np.sqrt(0.75))):
        placed, _ = turn_up(ball, up)
        assert mesh_deflection(placed) == first, up
        assert surface_mesh(placed).deflection == first, up


def test_turn_up_puts_the_direction_along_z():
    jack = samples.jack()
    turned, placement = turn_up(jack, (0.0, 0.0, -1.0))
    assert placement.turned and placement.angle == pytest.approx(np.pi)
    assert turned.Volume == pytest.approx(jack.Volume)
    box = turned.BoundBox
    assert (box.ZMin, box.ZMax) == pytest.approx((-jack.BoundBox.ZMax, -jack.BoundBox.ZMin))
    same, still = turn_up(jack, (0.0, 0.0, 1.0))
    assert not still.turned and same.BoundBox.ZMax == pytest.approx(jack.BoundBox.ZMax)


def test_every_candidate_plan_of_a_part_places_the_same_copy(App):
    """Each candidate plan places the part again: one copy per part and placement, so that
    what was meshed and measured of its faces for one candidate serves the next (a fresh
    copy each time re-meshed Pump_Nut's 17 curved faces for its whole twin). A copy, never
    the part itself, and never moved in place."""
    from freecad_conformal.jobs.plan import centred_if_off_platform

    jack = samples.jack()
    box = jack.BoundBox
    turned, _ = turn_up(jack, (0.0, 0.0, -1.0))
    again, _ = turn_up(jack, (0.0, 0.0, -1.0))
    upright, _ = turn_up(jack, (0.0, 0.0, 1.0))
    assert again is turned and upright is not turned and upright is not jack
    assert turn_up(jack.copy(), (0.0, 0.0, -1.0))[0] is not turned
    far = jack.copy()
    far.translate(App.Vector(900, 0, 0))
    machine = load_machine("trunnion_ac")
    centred, note = centred_if_off_platform(far, machine)
    assert note is not None and centred is not far
    assert centred_if_off_platform(far, machine)[0] is centred
    assert far.BoundBox.XMin == pytest.approx(box.XMin + 900)     # neither moved in place
    assert jack.BoundBox.ZMin == pytest.approx(box.ZMin) and jack.BoundBox.ZMax == pytest.approx(box.ZMax)


@pytest.mark.slow
def test_a_copy_not_turned_reads_the_faces_already_meshed(Part):
    """The orientation scans mesh the part as given; its copy as placed (+Z up) has the very
    same faces, so the mesh parts made for them serve it (points and normals bit for bit)
    and its mesh closes. A turned copy's faces are meshed for themselves."""
    from freecad_conformal.geometry.surface_mesh import face_part, mesh_deflection, surface_mesh

    part = Part.makeSphere(10.0).fuse(Part.makeCylinder(4.0, 20.0)).removeSplitter()
    deflection = mesh_deflection(part)
    given = [face_part(face, deflection) for face in part.Faces]
    placed, _ = turn_up(part, (0.0, 0.0, 1.0))
    assert all(a is b for a, b in zip((face_part(f, deflection) for f in placed.Faces), given))
    assert surface_mesh(placed) is not None
    turned, _ = turn_up(part, (1.0, 0.0, 0.0))
    parts = [face_part(face, deflection) for face in turned.Faces]
    assert not any(a is b for a, b in zip(parts, given) if a is not None)
    curved = next(i for i, p in enumerate(given) if p is not None and not p.planar)
    np.testing.assert_allclose(parts[curved].points[:, 0], -given[curved].points[:, 2], atol=1e-9)


def test_the_hinge_is_turned_until_the_trunnion_reaches_every_sub_part():
    """As modelled its lugs need the tool along −Z (A = 180°, beyond ±120°). A decomposition
    that builds the root along +Z of whatever it is given (left to "auto" the hinge is built
    turned over whole, support-free) is given the part turned over, lugs up."""
    from freecad_conformal.decomposition.decompose import decompose

    def root_up(placed, **options):
        return decompose(placed, **{**options, "root_direction": (0.0, 0.0, 1.0)})

    hinge = samples.hinge()
    options = PlanOptions(machine="trunnion_ac")
    placed, plan = machine_plan(hinge, options, decompose=root_up)
    check_reach(load_machine("trunnion_ac"), plan)
    assert any("part placed with its" in note for note in plan.notes)
    assert placed.Volume == pytest.approx(hinge.Volume, rel=1e-6)
    assert plan.support_area == 0.0
    result = run_job(placed, plan, options, part="hinge")
    assert 0.3 * hinge.Volume < result.material_volume < 0.9 * hinge.Volume


def test_a_root_given_stays_the_users_when_the_part_is_turned(monkeypatch):
    """`--root 0,0,1` is +Z of the part as given: turning the part does not turn the root
    with it behind the user's back, so the hinge's lugs (−Z from that root) stay out of the
    trunnion's reach in every placement, and the error says so. Laid out root up, every
    placement gives that same plan, and the trunnion reaches by tilt alone: the part is
    decomposed once, not six times (CrankArm with --root 0,0,-1: 25 s)."""
    from freecad_conformal.decomposition import decompose as decomposition

    made = []
    real = decomposition.decompose
    monkeypatch.setattr(decomposition, "decompose",
                        lambda *args, **kwargs: made.append(1) or real(*args, **kwargs))
    with pytest.raises(PlanError, match=r"A = 180\.000°.*turning the part on the table would "
                                        r"give the same plan"):
        machine_plan(samples.hinge(), PlanOptions(machine="trunnion_ac", root=(0.0, 0.0, 1.0)))
    assert len(made) == 1


def test_a_machine_that_reaches_by_tilt_alone():
    from freecad_conformal.jobs.plan import reach_by_tilt

    for name in ("trunnion_ac", "head_a_table_c", "three_axis"):
        assert reach_by_tilt(load_machine(name)), name
    # A only, about X: the tool leans in the YZ plane and nowhere else.
    assert not reach_by_tilt(load_machine("rotary_mandrel"))


def test_no_reachable_placement_names_every_one_tried():
    def along_x(shape, placement):
        return BuildPlan([SubPart(0, shape, np.array([1.0, 0.0, 0.0]))], order=[0])

    machine = load_machine("three_axis")
    with pytest.raises(PlanError, match=r"no placement of the part .* \(\+0, \+0, -1\) up: machine "
                                        r"'Plain 3-axis' cannot point"):
        reachable_plan(samples.jack(), along_x, lambda plan: check_reach(machine, plan))


def test_a_copy_not_turned_keeps_the_overhang_measured_of_the_part(monkeypatch):
    """The search scans the part's overhang in every candidate direction, and the
    decomposition its copy as placed (+Z up) again: the copy has the very faces, so it keeps
    what was measured, for a solid and for the solid inside a one-solid compound. A turned
    copy measures its own."""
    from freecad_conformal.freecad_env import import_freecad
    from freecad_conformal.geometry import overhang

    _, Part = import_freecad()
    part = Part.Compound([samples.t_block()])
    directions = [np.array(d, dtype=float) for d in ((0, 0, 1), (0, 0, -1), (1, 0, 0))]
    given = [overhang.overhang_area(part.Solids[0], d) for d in directions]
    measured = []
    real = overhang.overhang_report
    monkeypatch.setattr(overhang, "overhang_report",
                        lambda shape, *args, **kwargs: measured.append(shape) or real(
                            shape, *args, **kwargs))
    placed, _ = turn_up(part, (0.0, 0.0, 1.0))
    assert [overhang.overhang_area(placed.Solids[0], d) for d in directions] == given
    assert measured == []
    turned, _ = turn_up(part, (1.0, 0.0, 0.0))
    overhang.overhang_area(turned.Solids[0], directions[0])
    assert len(measured) == 1


def test_a_job_starts_with_the_shape_caches_empty():
    """A process planning part after part (`batch`, macros) keeps no shapes of the last job:
    the copy a placement cached before a job is not the one handed out after it."""
    from freecad_conformal.jobs.job import plan_job

    part = samples.l_block()
    first, _ = turn_up(part, (1.0, 0.0, 0.0))
    assert turn_up(part, (1.0, 0.0, 0.0))[0] is first
    plan_job(samples.t_block(), PlanOptions(decompose=False, root=(0.0, 0.0, 1.0)))
    assert turn_up(part, (1.0, 0.0, 0.0))[0] is not first


def test_only_a_machine_without_tilt_builds_along_z_alone():
    from freecad_conformal.jobs.plan import machine_tilts

    assert not machine_tilts(load_machine("three_axis"))
    for name in ("trunnion_ac", "head_a_table_c", "rotary_mandrel"):
        assert machine_tilts(load_machine(name)), name


def test_a_machine_without_tilt_builds_the_part_whole_in_its_best_orientation(App):
    """A plain 3-axis printer cannot build a sub-part along any direction but +Z: the part
    is not decomposed (trying the six placements for one cost CrankArm 18 s before it was
    built whole anyway) but built whole, with support, along its direction of least
    overhang, and the summary says why the support is left."""
    from freecad_conformal.decomposition.subparts import WHOLE_ON_MACHINE
    from freecad_conformal.geometry.overhang import best_single_direction, overhang_area
    from freecad_conformal.jobs.plan import check_options, choose_plan
    from freecad_conformal.jobs.report import support_text

    def no_decomposition(*_args, **_kwargs):
        raise AssertionError("a machine without tilt decomposed the part")

    jack = samples.jack()
    jack.rotate(App.Vector(0, 0, 0), App.Vector(1, 0, 0), 30)
    options = PlanOptions(machine="three_axis")
    choice = choose_plan(jack, options, check_options(jack, options), decompose=no_decomposition)
    plan = choice.plan
    _, least = best_single_direction(jack)
    assert least < overhang_area(jack, (0.0, 0.0, 1.0)) - 1.0     # as modelled is not the best
    assert len(plan.subparts) == 1 and plan.support_reason == WHOLE_ON_MACHINE
    assert plan.support_area == pytest.approx(least, rel=1e-6)
    np.testing.assert_allclose(plan.subparts[0].build_direction, (0.0, 0.0, 1.0), atol=1e-9)
    said = support_text(plan, False, False)
    assert "the machine cannot tilt the tool" in said
    # and that the G-code has none: Conformal prints no support
    assert "which this G-code does not print" in said
    assert any("cannot tilt the tool off +Z" in note for note in plan.notes)


def test_each_solid_stands_in_its_own_best_orientation_on_a_machine_without_tilt(App, Part):
    """Two T-blocks, one as modelled (its flange overhangs) and one turned over (support-free
    as it is): on a 3-axis printer each is built whole along its own direction of least
    overhang, so neither needs support; as placed the first would."""
    from freecad_conformal.jobs.plan import check_options, choose_plan

    upright = samples.t_block()
    over = samples.t_block()
    over.rotate(App.Vector(0, 0, 0), App.Vector(1, 0, 0), 180)
    over.translate(App.Vector(upright.BoundBox.XLength + 20.0, 0, 0))
    part = Part.makeCompound([upright, over])
    options = PlanOptions(machine="three_axis")
    plan = choose_plan(part, options, check_options(part, options)).plan
    assert len(plan.subparts) == 2 and plan.support_area == pytest.approx(0.0, abs=1e-6)
    assert sorted(s.volume for s in plan.subparts) == pytest.approx(
        sorted([upright.Volume, over.Volume]), rel=1e-9)
    for sub in plan.subparts:
        np.testing.assert_allclose(sub.build_direction, (0.0, 0.0, 1.0), atol=1e-9)


def test_a_machine_without_tilt_gets_planar_layers_where_a_bend_would_tilt_them(App, Part):
    """A square bar bent through 90°: along +Z its 3-D layers follow the bend, tilting the
    tool, which the trunnion takes and a 3-axis printer cannot (the pipe elbow's post was
    refused at its first tilted layer after 19 s of planning). On the printer its layers
    are planar and it is posted."""
    from freecad_conformal.jobs.plan import buildable_layers

    V = App.Vector
    face = Part.Face(Part.makePolygon([V(20, -5, 0), V(30, -5, 0), V(30, 5, 0), V(20, 5, 0),
                                       V(20, -5, 0)]))
    bar = face.revolve(V(0, 0, 0), V(0, -1, 0), 90)
    tilted = {}
    for name in ("trunnion_ac", "three_axis"):
        options = PlanOptions(machine=name, decompose=False)
        placed, plan = machine_plan(bar, options)
        result = run_job(placed, plan, options, part="bent bar")
        tilted[name] = sum(layer.tilted for layer in result.layers[0])
        assert result.post.text
    assert tilted["trunnion_ac"] > 10 and tilted["three_axis"] == 0
    settings = PlanOptions().layers
    assert buildable_layers(settings, load_machine("trunnion_ac"), 0.4) is settings
