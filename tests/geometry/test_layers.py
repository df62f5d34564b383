"""Layers per sub-part: uniform, adaptive (volume difference), cusp, 3-D tilted, refusals."""
from __future__ import annotations

import math

import numpy as np
import pytest

from freecad_conformal.errors import PlanError
from freecad_conformal.geometry import samples
from freecad_conformal.geometry.overhang import overhang_area
from freecad_conformal.layers.model import LayerSettings, check_thickness, thickness_report
from freecad_conformal.layers.plan import plan_layers
from freecad_conformal.layers.planar import volume_difference
from freecad_conformal.decomposition.subparts import SubPart


def _sub(shape, direction=(0, 0, 1)):
    # With the overhang planar layers leave, as a plan's sub-part has it: only then are its
    # layers tilted (layers/plan.needs_tilt).
    d = np.array(direction, dtype=float)
    return SubPart(index=0, shape=shape, build_direction=d, overhang_area=overhang_area(shape, d))


@pytest.fixture(scope="module")
def ring(App, Part):
    """A square bar (10 × 10 mm) bent through 90° about the Y axis: rises from the bed and
    ends pointing along −X. Its centroidal axis bends steadily, radius 25 mm."""
    V = App.Vector
    face = Part.Face(Part.makePolygon([V(20, -5, 0), V(30, -5, 0), V(30, 5, 0), V(20, 5, 0), V(20, -5, 0)]))
    return face.revolve(V(0, 0, 0), V(0, -1, 0), 90)


@pytest.fixture(scope="module")
def pyramid_on_box(App, Part):
    """A 20 mm cube under a 10 mm high square frustum: vertical walls, then 45° walls."""
    V = App.Vector
    cube = Part.makeBox(20, 20, 10)
    top = Part.makeLoft([Part.makePolygon([V(0, 0, 10), V(20, 0, 10), V(20, 20, 10), V(0, 20, 10), V(0, 0, 10)]),
                         Part.makePolygon([V(10, 10, 20) + V(-0.5, -0.5, 0), V(10.5, 9.5, 20), V(10.5, 10.5, 20),
                                           V(9.5, 10.5, 20), V(9.5, 9.5, 20)])], True)
    return cube.fuse(top).removeSplitter()


def test_uniform_layers_integrate_the_volume():
    bracket = samples.overhang_bracket()
    layers = plan_layers(_sub(bracket), LayerSettings(thickness=0.5))
    assert len(layers) == 100
    assert thickness_report(layers) == pytest.approx((0.5, 0.5))
    volume = sum(layer.area * layer.thickness for layer in layers)
    assert volume == pytest.approx(bracket.Volume, rel=1e-3)
    np.testing.assert_allclose(layers[0].top_point, [0, 0, 0.5])
    assert not any(layer.tilted for layer in layers)


def test_layers_along_another_direction():
    jack = samples.jack()
    layers = plan_layers(_sub(jack, (1, 0, 0)), LayerSettings(thickness=1.0, tilt=False))
    assert len(layers) == 62
    np.testing.assert_allclose(layers[0].top_normal, [1, 0, 0])
    assert layers[0].top_point @ np.array([1, 0, 0]) == pytest.approx(-31 + 1.0)


@pytest.mark.slow
def test_adaptive_is_thick_on_vertical_walls_and_thin_on_slopes(pyramid_on_box):
    settings = LayerSettings(mode="adaptive", thickness=0.2, min_thickness=0.1, max_thickness=0.4,
                             max_volume_difference=1.0)
    layers = plan_layers(_sub(pyramid_on_box), settings)
    low = [l for l in layers if l.top_point[2] < 9.5]
    high = [l for l in layers if 11 < l.top_point[2] < 19]
    assert all(l.thickness == pytest.approx(0.4) for l in low)
    assert max(l.thickness for l in high) < 0.4
    assert min(l.thickness for l in layers) >= 0.1 - 1e-9
    assert layers[-1].top_point[2] == pytest.approx(20.0, abs=1e-6)


def test_volume_difference_formula(App, Part):
    """Δ·area(A_low △ A_up)/2 for a 45° wall step: sections of a frustum 1 mm apart."""
    from freecad_conformal.geometry.sections import PlanarSlicer

    cone = Part.makeCone(10, 5, 5)            # radius falls 1 mm per mm
    slicer = PlanarSlicer(cone)
    low, up = slicer.sections([1.0, 2.0])
    expected = 0.5 * 1.0 * math.pi * (9 ** 2 - 8 ** 2)
    assert volume_difference(low, up, 1.0) == pytest.approx(expected, rel=1e-3)


def test_cusp_mode_thins_layers_on_slopes(pyramid_on_box):
    settings = LayerSettings(mode="cusp", thickness=0.2, min_thickness=0.1, max_thickness=0.4,
                             max_cusp=0.1)
    layers = plan_layers(_sub(pyramid_on_box), settings)
    below = [l.thickness for l in layers if l.top_point[2] < 9.5]
    slope = [l.thickness for l in layers if 11 < l.top_point[2] < 19]
    assert below and min(below) == pytest.approx(0.4)
    # cusp = Δ·|n·d| = Δ·cos 45° <= 0.1 -> Δ <= 0.141, from the 0.4 trial shrunk by quarters
    assert max(slope) <= 0.1 / math.cos(math.pi / 4) + 1e-9


def test_tilted_layers_follow_a_bent_bar(ring):
    settings = LayerSettings(thickness=0.5, min_thickness=0.25, max_thickness=0.75, tilt=True)
    layers = plan_layers(_sub(ring), settings)
    tilted = [l for l in layers if l.tilted]
    assert len(tilted) > 0.8 * len(layers)
    # the last planes face along the bar's end (−X)
    assert layers[-1].top_normal @ np.array([-1.0, 0, 0]) > math.cos(math.radians(5))
    check_thickness(layers, settings)
    thin, thick = thickness_report(layers)
    assert 0.25 <= thin < thick <= 0.75
    # inner radius 20, outer 30: a wedge slab is about 20/30 as thick inside as outside
    middle = layers[len(layers) // 2]
    assert middle.thickness_min / middle.thickness_max == pytest.approx(20 / 30, abs=0.08)
    volume = sum(l.area * l.thickness for l in layers)
    assert volume == pytest.approx(ring.Volume, rel=0.02)


def test_tight_bounds_keep_tilted_layers_inside_them(ring):
    """Bisection towards the lower plane trades tilt for thickness: every slab stays within
    [ΔL_min, ΔL_max] even where the bar bends faster than the bounds allow to follow."""
    settings = LayerSettings(thickness=1.0, min_thickness=0.95, max_thickness=1.05, tilt=True)
    layers = plan_layers(_sub(ring), settings)
    check_thickness(layers, settings)
    assert any(layer.tilted for layer in layers)


def test_tilted_layers_outside_bounds_are_refused_by_name(ring):
    layers = plan_layers(_sub(ring), LayerSettings(thickness=1.0, min_thickness=0.5, max_thickness=1.5,
                                                   tilt=True))
    with pytest.raises(PlanError, match=r"layer \d+ of sub-part 0 is 0\.\d+ to 1\.\d+ mm thick, "
                                        r"outside \[0.9, 1.1\] mm"):
        check_thickness(layers, LayerSettings(thickness=1.0, min_thickness=0.9, max_thickness=1.1))


def test_straight_parts_get_no_tilt():
    layers = plan_layers(_sub(samples.overhang_bracket()), LayerSettings(thickness=1.0, tilt=True))
    assert not any(layer.tilted for layer in layers)


def test_check_thickness_names_the_layer():
    layers = plan_layers(_sub(samples.jack()), LayerSettings(thickness=1.0, tilt=False))
    with pytest.raises(PlanError, match=r"layer 0 of sub-part 0 is 1.0000 to 1.0000 mm thick, outside \[0.2, 0.6\]"):
        check_thickness(layers, LayerSettings(thickness=0.4, min_thickness=0.2, max_thickness=0.6))


@pytest.mark.parametrize("settings, message", [
    (LayerSettings(thickness=0.0), "layer height must be a positive"),
    (LayerSettings(thickness=-0.2), "layer height must be a positive"),
    (LayerSettings(thickness=float("nan")), "layer height must be a positive"),
    (LayerSettings(thickness=0.2, min_thickness=0.3, max_thickness=0.25), "exceeds the maximum"),
    (LayerSettings(mode="spiral"), "layer mode 'spiral'"),
])
def test_bad_layer_settings(settings, message):
    with pytest.raises(PlanError, match=message):
        plan_layers(_sub(samples.jack()), settings)


def test_layer_larger_than_the_part_is_refused():
    with pytest.raises(PlanError, match="larger than the part"):
        LayerSettings(thickness=80.0).validate(part_size=62.0)


def test_a_default_layer_bound_says_where_it_comes_from_and_rounding_is_no_excess():
    """A 0.3 mm part was refused: "maximum layer height 0.3 mm is larger than the part
    (0.300 mm)": 1.5 x 0.2 is 0.30000000000000004, and the user had set no maximum."""
    LayerSettings(thickness=0.2).validate(part_size=0.3)
    with pytest.raises(PlanError, match=r"maximum layer height 0.3 mm \(1.5 x the layer height\)"):
        LayerSettings(thickness=0.2).validate(part_size=0.25)
    with pytest.raises(PlanError, match=r"maximum layer height 0.28 mm is larger"):
        LayerSettings(thickness=0.2, max_thickness=0.28).validate(part_size=0.25)


def _loft(App, Part):
    """A solid with B-spline faces: lofted through a circle and two ellipses."""
    V = App.Vector
    wires = [Part.Wire(Part.makeCircle(6.0, V(0, 0, 0))),
             Part.Wire(Part.Ellipse(V(1, 0, 8), 7.0, 4.0).toShape()),
             Part.Wire(Part.makeCircle(5.0, V(2, 0, 16)))]
    return Part.makeLoft(wires, True, False)


def test_layers_are_the_same_on_two_processes_as_on_one(App, Part):
    """The plan's sections spread over worker processes (`LayerSettings.workers`) give the
    same layers, in the same order, to the last bit as one process (inside FreeCAD plans
    are cut in one process, on the command line in several: the G-code must not differ)."""
    for shape, direction in ((samples.jack(), (1, 0, 0)), (_loft(App, Part), (0, 0, 1))):
        one = plan_layers(_sub(shape, direction), LayerSettings(thickness=1.0, tilt=False, workers=1))
        two = plan_layers(_sub(shape, direction), LayerSettings(thickness=1.0, tilt=False, workers=2))
        assert [layer.section_height for layer in one] == [layer.section_height for layer in two]
        for a, b in zip(one, two):
            assert a.region.equals_exact(b.region, 0.0)


def test_tilted_layers_are_the_same_with_their_middles_cut_on_a_worker(ring):
    """3-D layers' regions (cut on each slab's middle plane) come from a worker process
    when workers are asked for: the same layers, to the last bit, as cut here."""
    layers = {}
    for workers in (1, 2):
        settings = LayerSettings(thickness=0.5, min_thickness=0.25, max_thickness=0.75,
                                 tilt=True, workers=workers)
        layers[workers] = plan_layers(_sub(ring), settings)
    assert sum(layer.tilted for layer in layers[1]) > 10
    assert len(layers[1]) == len(layers[2])
    for a, b in zip(layers[1], layers[2]):
        assert a.region.equals_exact(b.region, 0.0)
        assert np.array_equal(a.top_point, b.top_point) and np.array_equal(a.top_normal, b.top_normal)


def test_a_plane_stream_worker_that_fails_is_reported(App, Part):
    """A worker's error reaches the caller as a GeometryError naming it, not a hang."""
    from freecad_conformal.errors import GeometryError
    from freecad_conformal.geometry.plane_stream import PlaneStream
    from freecad_conformal.geometry.sections import PlanarSlicer

    stream = PlaneStream(PlanarSlicer(Part.makeBox(10, 10, 10)), 10, workers=2)
    stream.submit(np.array([5.0, 5.0, 5.0]), np.array([0.0, 0.0, 1.0]))
    stream.submit(np.array([5.0, 5.0, 5.0]), np.array([0.0, 0.0, 0.0]))   # no normal
    with pytest.raises(GeometryError, match="section worker failed"):
        stream.results()


def test_freeform_faces_weigh_more_in_the_work_that_calls_for_workers(App, Part):
    from freecad_conformal.geometry import section_pool as pool
    from freecad_conformal.geometry.sections import PlanarSlicer

    assert pool.section_work(PlanarSlicer(Part.makeBox(1, 1, 1))) == 6
    loft = _loft(App, Part)
    freeform = sum(type(f.Surface).__name__ not in pool.ANALYTIC_SURFACES for f in loft.Faces)
    assert freeform >= 1
    assert pool.section_work(PlanarSlicer(loft)) == (
        len(loft.Faces) - freeform + freeform * pool.FREEFORM_FACE_WORK)


def test_a_negative_worker_count_is_refused_by_name():
    with pytest.raises(PlanError, match="workers must be a whole number, 0 or more, got -1"):
        plan_layers(_sub(samples.jack()), LayerSettings(workers=-1))


def test_automatic_workers_fill_the_cores_only_for_large_jobs_in_a_main_process():
    from freecad_conformal.geometry import section_pool as pool

    large = pool.MIN_PARALLEL_WORK
    assert pool.useful_workers(pool.AUTO, large) == pool.default_workers()
    assert pool.useful_workers(pool.AUTO, large - 1) == 1
    assert pool.useful_workers(3, 1) == 3       # asked for: given, whatever the size


def _useful_in_child(queue) -> None:
    from freecad_conformal.geometry import section_pool as pool

    queue.put((pool.useful_workers(pool.AUTO, 10 ** 9), pool.useful_workers(2, 10 ** 9)))


def test_a_worker_process_cuts_its_sections_itself():
    """A batch worker already fills the cores: AUTO stays in it; a daemonic one (which may
    have no children) does so even when asked for more."""
    import multiprocessing

    context = multiprocessing.get_context("spawn")
    queue = context.Queue()
    child = context.Process(target=_useful_in_child, args=(queue,), daemon=True)
    child.start()
    answers = queue.get(timeout=120)
    child.join()
    assert answers == (1, 1)


def test_a_layer_sampled_through_a_vertex_is_cut_beside_it_face_by_face(App, Part):
    """A step at 7.5 mm meets the middle plane of the 38th 0.2 mm layer: that plane is
    moved off the step by RETRY_NUDGE instead of going to the Boolean. Below and above the
    step the walls run straight: one plane of each run is cut, the others are moved."""
    from freecad_conformal.geometry.sections import RETRY_NUDGE, PlanarSlicer
    from freecad_conformal.layers.planar import _uniform_bounds, planar_layers

    step = Part.makeBox(10, 10, 15).cut(Part.makeBox(5, 10, 7.5, App.Vector(0, 0, 7.5)))
    slicer = PlanarSlicer(step, (0, 0, 1))
    layers = planar_layers(0, slicer, _uniform_bounds(0.0, 15.0, 0.2), workers=1)
    assert slicer.counts == {"face_by_face": 2, "boolean": 0}
    at_step = layers[37]
    assert at_step.section_height == pytest.approx(7.5 + RETRY_NUDGE, abs=1e-12)
    assert at_step.region.area == pytest.approx(50.0, rel=1e-9)
    assert [layer.section_height for layer in layers[36:39:2]] == pytest.approx([7.3, 7.7], abs=1e-12)
