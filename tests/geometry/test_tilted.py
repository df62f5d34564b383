"""3-D layers: robustness (no NaN planes, exact snap to the build direction, bounded slicer
cache, no tilting where the section is too wide to turn) on top of test_layers' geometry."""
from __future__ import annotations

import math

import numpy as np
import pytest
from shapely.geometry import MultiPolygon, box

from freecad_conformal.errors import PlanError
from freecad_conformal.geometry import samples
from freecad_conformal.geometry.frames import LayerFrame
from freecad_conformal.geometry.overhang import overhang_area
from freecad_conformal.layers import following, tilted
from freecad_conformal.layers.model import Layer, LayerSettings, check_thickness
from freecad_conformal.layers.plan import plan_layers
from freecad_conformal.decomposition.subparts import SubPart

Z = np.array([0.0, 0.0, 1.0])


def _sub(shape, direction=(0, 0, 1), overhang=1.0):
    # Overhanging by default, so that the bend rules decide: a sub-part planar layers print
    # support-free is never tilted (test_a_support_free_sub_part_keeps_planar_layers).
    return SubPart(index=3, shape=shape, build_direction=np.array(direction, dtype=float),
                   overhang_area=overhang)


def _layer(region, thickness=0.2) -> Layer:
    frame = LayerFrame.for_direction(Z)
    return Layer(subpart=0, index=0, frame=frame, section_height=0.0, region=MultiPolygon([region]),
                 top_point=thickness * Z, top_normal=Z, thickness_min=thickness,
                 thickness_max=thickness)


def test_turn_capacity_is_the_slack_over_the_farthest_point():
    layer = _layer(box(-3, -4, 3, 4))                      # farthest corner 5 mm from the centre
    assert tilted.turn_capacity(layer, 0.1, 0.3) == pytest.approx(math.atan2(0.1, 5.0))
    assert tilted.turn_capacity(layer, 0.2, 0.3) == 0.0    # no room below: no turn


@pytest.fixture(scope="module")
def rod():
    return samples.inclined_rod()


@pytest.fixture(scope="module")
def branch55():
    """A square branch leaning 55° off a block: its underside overhangs planar layers
    along +Z, and following it spares that."""
    return samples.branch45(lean_deg=55.0)


@pytest.mark.slow
def test_a_leaning_branch_tilts_and_its_planes_are_square_or_clearly_tilted(branch55):
    settings = LayerSettings(thickness=0.2, tilt=True)
    layers = plan_layers(_sub(branch55, overhang=overhang_area(branch55, Z)), settings)
    check_thickness(layers, settings)
    assert sum(layer.tilted for layer in layers) > 10
    for layer in layers:
        assert np.all(np.isfinite(layer.top_point)) and np.all(np.isfinite(layer.top_normal))
        angle = math.acos(min(1.0, float(layer.top_normal @ Z)))
        # a hair off the build direction meets faces square to it almost tangentially
        assert angle == 0.0 or angle >= tilted.PARALLEL_ANGLE


@pytest.mark.slow
def test_a_rod_is_followed_only_where_planar_layers_overhang_and_following_spares_it(
        App, Part, rod, branch55):
    """3-D layers cost planning (three OCC cuts a layer) and print time; they are made only
    where following the bend spares a real share of the overhang planar layers leave."""
    settings = LayerSettings(thickness=0.2, tilt=True)
    # leaning 30°: planar layers print it support-free, its 3-D layers only cost (0.6 %
    # more time, 1.6x the planning)
    assert overhang_area(rod, Z) < 1e-3
    assert not any(layer.tilted for layer in plan_layers(_sub(rod, overhang=0.0), settings))
    # a branch leaning 55°: following spares its underside
    steep = _sub(branch55, overhang=overhang_area(branch55, Z))
    planar = plan_layers(steep, LayerSettings(thickness=0.2, tilt=False))
    assert following.spared_overhang(steep, planar) > 0.9 * steep.overhang_area
    assert any(layer.tilted for layer in plan_layers(steep, settings))
    # leaning 30° under a flat cap: the cap's underside overhangs, but no plane following
    # the rod turns to it (the connecting rod's boss: 0.7 % spared for 5 s of planning)
    V = App.Vector
    top = V(40.0 * math.sin(math.radians(30.0)), 0, 8.0 + 40.0 * math.cos(math.radians(30.0)))
    capped = rod.fuse(Part.makeCylinder(12.0, 2.0, top - V(0, 0, 2.5))).removeSplitter().Solids[0]
    sub = _sub(capped, overhang=overhang_area(capped, Z))
    planar = plan_layers(sub, LayerSettings(thickness=0.2, tilt=False))
    assert sub.overhang_area > 100.0 and tilted.axis_bends(planar, settings.bounds)
    assert following.spared_overhang(sub, planar) < 0.05 * sub.overhang_area
    assert not any(layer.tilted for layer in plan_layers(sub, settings))


@pytest.mark.slow
def test_a_rod_whose_rim_pokes_below_its_plate_is_followed_from_its_first_centroid():
    """Leaning 55°, the rod's rim pokes 0.7 mm below its plate: the lowest section is a
    sliver without a finite centroid, where the chain ended before its first layer and
    the whole stack came out planar. It starts from the first section with a centroid."""
    rod = samples.inclined_rod(tilt_deg=55.0)
    sub = _sub(rod, overhang=overhang_area(rod, Z))
    assert sub.overhang_area > 100.0
    layers = plan_layers(sub, LayerSettings(thickness=0.2, tilt=True))
    check_thickness(layers, LayerSettings(thickness=0.2))
    assert sum(layer.tilted for layer in layers) > 40
    # the stack holds the part: only the rim's sliver under the first centroid is left out
    volume = sum(layer.region.area * 0.5 * (layer.thickness_min + layer.thickness_max)
                 for layer in layers)
    assert volume == pytest.approx(rod.Volume, rel=0.01)


def test_a_face_exactly_at_the_overhang_limit_does_not_overhang():
    """branch45's underside leans exactly 45°: whether it overhung was rounding's call
    (n·d = −0.7071067811865476 against −sin 45° = −0.7071067811865475: 50 mm², and 26
    of its layers tilted for nothing). At the limit it prints without support, whichever
    way the rounding falls (mirrored, leaning the other way)."""
    for lean in (45.0, -45.0):
        branch = samples.branch45(lean_deg=lean)
        assert overhang_area(branch, Z) < 1e-6
        layers = plan_layers(_sub(branch, overhang=overhang_area(branch, Z)), LayerSettings())
        assert not any(layer.tilted for layer in layers)
    assert overhang_area(samples.branch45(lean_deg=46.0), Z) > 10.0


def test_a_wide_leaning_slab_is_not_tilted(App, Part):
    """A 60 mm wide slab leaning 10°: its centroids drift like a bend, but a plane can turn
    only ~0.1° per 0.2 mm layer over it, so it stays planar (and fast)."""
    V = App.Vector
    lean = math.tan(math.radians(10.0)) * 20.0
    bottom = Part.makePolygon([V(0, 0, 0), V(60, 0, 0), V(60, 60, 0), V(0, 60, 0), V(0, 0, 0)])
    top = Part.makePolygon([V(lean, 0, 20), V(60 + lean, 0, 20), V(60 + lean, 60, 20),
                            V(lean, 60, 20), V(lean, 0, 20)])
    slab = Part.makeLoft([bottom, top], True)
    planar = plan_layers(_sub(slab), LayerSettings(thickness=0.2, tilt=False))
    assert tilted.axis_bends(planar)                               # the drift alone says "bend"
    assert not tilted.axis_bends(planar, LayerSettings().bounds)   # but it cannot be followed
    layers = plan_layers(_sub(slab), LayerSettings(thickness=0.2, tilt=True))
    assert not any(layer.tilted for layer in layers)


def test_sections_refuse_a_non_finite_plane_and_keep_few_slicers(rod):
    sections = tilted._Sections(rod, 3)
    with pytest.raises(PlanError, match=r"sub-part 3: a 3-D layer plane is not finite"):
        sections.at(np.array([0.0, np.nan, 5.0]), Z)
    for k in range(10):
        normal = np.array([math.sin(0.01 * k), 0.0, math.cos(0.01 * k)])
        sections.at(np.array([0.0, 0.0, 10.0]), normal)
    assert len(sections._slicers) == tilted.SLICER_CACHE and sections.cuts == 10


def test_a_plane_probed_then_taken_is_cut_once(rod):
    # Where the axis runs straight the layer's plane is its probe's: one cut, not two; any
    # other plane (another height, another normal) is cut afresh.
    sections = tilted._Sections(rod, 0)
    probe = sections.at(np.array([0.0, 0.0, 4.0]), Z)
    assert sections.at(np.array([0.0, 0.0, 4.0]), Z) is probe and sections.cuts == 1
    higher = sections.at(np.array([0.0, 0.0, 4.2]), Z)
    assert higher is not probe and higher.height == pytest.approx(probe.height + 0.2)
    tilted_normal = np.array([math.sin(0.05), 0.0, math.cos(0.05)])
    assert sections.at(np.array([0.0, 0.0, 4.2]), tilted_normal) is not higher
    assert sections.cuts == 3


def test_section_centroid_of_nothing_is_none(rod):
    sections = tilted._Sections(rod, 0)
    assert tilted.section_centroid(sections.at(np.array([0.0, 0.0, 500.0]), Z)) is None
    inside = tilted.section_centroid(sections.at(np.array([0.0, 0.0, 4.0]), Z))
    np.testing.assert_allclose(inside, [0.0, 0.0, 4.0], atol=1e-6)


def test_a_section_growing_on_one_side_is_no_bend(App, Part):
    """A 10 mm bar whose +X side flares out to 20 mm over 10 mm (Pump_Nut's flange): the
    centroid drifts sideways (~27° over 2 mm) with the area within the ratio at the bottom,
    but the section grows instead of moving."""
    V = App.Vector
    bottom = Part.makePolygon([V(0, 0, 0), V(10, 0, 0), V(10, 10, 0), V(0, 10, 0), V(0, 0, 0)])
    top = Part.makePolygon([V(0, 0, 10), V(20, 0, 10), V(20, 10, 10), V(0, 10, 10), V(0, 0, 10)])
    flare = Part.makeLoft([bottom, top], True)
    layers = plan_layers(_sub(flare), LayerSettings(thickness=0.2, tilt=True))
    assert not any(layer.tilted for layer in layers)
    assert tilted._shape_change(layers[0], layers[10]) > tilted.BEND_SHAPE_CHANGE
    assert layers[10].area / layers[0].area < tilted.BEND_AREA_RATIO


def test_a_side_growing_within_the_shape_change_is_no_bend():
    """A 10 × 10 mm bar with a 10 mm wide boss growing out of its +X side, 0.03 mm a layer
    (a pedestal on an ellipsoid's side, a fan blade seen along the hub): the centroid leans
    ~4° to the same side window after window and the section changes by under 10 % of its
    area, as a bend's does; but moving it by the drift misses the next section more than
    leaving it does. The bar moved by the same drift is a bend."""
    frame = LayerFrame.for_direction(Z)
    bounds = LayerSettings().bounds

    def stack(regions):
        return [Layer(subpart=0, index=k, frame=frame, section_height=(k + 0.5) * 0.2,
                      region=MultiPolygon([region]), top_point=(k + 1) * 0.2 * Z,
                      top_normal=Z, thickness_min=0.2, thickness_max=0.2)
                for k, region in enumerate(regions)]

    grown = stack([box(-5, -5, 5, 5).union(box(5 - 1e-9, -5, 5 + 0.03 * k, 5)) if k else
                   box(-5, -5, 5, 5) for k in range(60)])
    lean = np.degrees(np.arctan2(grown[40].region.centroid.x - grown[30].region.centroid.x, 2.0))
    assert lean > np.degrees(tilted.BEND_MIN_ANGLE)
    assert tilted._shape_change(grown[30], grown[40]) < tilted.BEND_SHAPE_CHANGE
    assert not tilted.axis_bends(grown, bounds)
    drifts = [layer.region.centroid.x for layer in grown]
    moved = stack([box(-5 + x, -5, 5 + x, 5) for x in drifts])
    assert tilted.axis_bends(moved, bounds)


def _stack(shifts, thickness=0.2) -> list[Layer]:
    """Layers of a 4 × 4 mm bar whose section is moved sideways (x) by `shifts[k]` at layer k."""
    frame = LayerFrame.for_direction(Z)
    return [Layer(subpart=0, index=k, frame=frame, section_height=(k + 0.5) * thickness,
                  region=MultiPolygon([box(-2 + s, -2, 2 + s, 2)]),
                  top_point=(k + 1) * thickness * Z, top_normal=Z, thickness_min=thickness,
                  thickness_max=thickness) for k, s in enumerate(shifts)]


def test_a_bend_leans_over_two_windows_a_step_aside_is_no_bend():
    bounds = LayerSettings().bounds
    # leaning 14° all the way: a bend
    assert tilted.axis_bends(_stack([0.05 * k for k in range(60)]), bounds)
    # straight, stepping 0.5 mm aside over one 2 mm window (a thread's end, a fillet): the
    # window alone leans 14°, the next not at all
    steps = [0.0] * 20 + [0.05 * k for k in range(1, 11)] + [0.5] * 30
    assert not tilted.axis_bends(_stack(steps), bounds)
    # aside and back (the centroid of a helix's end): no bend either
    wobble = [0.0] * 20 + [0.05 * k for k in range(1, 11)] + [0.5 - 0.05 * k for k in range(1, 11)]
    assert not tilted.axis_bends(_stack(wobble + [0.0] * 20), bounds)
