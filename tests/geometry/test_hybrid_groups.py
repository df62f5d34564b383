"""Runs of 3-D layers deposited as planar layers and faced once (paths/hybrid_groups.py)."""
from __future__ import annotations

import math

import numpy as np
import pytest
from shapely.geometry import MultiPolygon, box

from freecad_conformal.geometry import samples
from freecad_conformal.geometry.frames import LayerFrame
from freecad_conformal.geometry.support import layered_support_volume, support_volume
from freecad_conformal.jobs.job import plan_job
from freecad_conformal.jobs.options import plan_options
from freecad_conformal.layers.model import Layer
from freecad_conformal.paths.hybrid_groups import _below_plane, wedge_height

HYBRID = {"process": "hybrid", "tool": "laser_powder", "machine": "hybrid_ac",
          "layer_height": 0.5}


def _tilted(normal) -> np.ndarray:
    n = np.asarray(normal, dtype=float)
    return n / np.linalg.norm(n)


def test_below_a_tilted_plane_keeps_the_half_under_it():
    frame = LayerFrame.for_direction((0, 0, 1))
    square = MultiPolygon([box(-10, -10, 10, 10)])
    # plane through the origin leaning about Y: below it where x < 0 at height 0
    normal = _tilted((1, 0, 1))
    kept = _below_plane(square, frame, 0.0, np.zeros(3), normal)
    assert kept.area == pytest.approx(200.0)
    assert kept.bounds[2] == pytest.approx(0.0)
    # at height 2 the plane is crossed at x = -2
    kept = _below_plane(square, frame, 2.0, np.zeros(3), normal)
    assert kept.bounds[2] == pytest.approx(-2.0)
    # a parallel plane keeps all or nothing
    assert _below_plane(square, frame, 1.0, np.array([0, 0, 2.0]), np.array([0, 0, 1.0])).area == 400
    assert _below_plane(square, frame, 3.0, np.array([0, 0, 2.0]), np.array([0, 0, 1.0])).is_empty


def test_wedge_height_is_the_far_side_of_the_top_plane():
    frame = LayerFrame.for_direction((0, 0, 1))
    layer = Layer(subpart=0, index=0, frame=frame, section_height=0.25,
                  region=MultiPolygon([box(0, 0, 10, 4)]), top_point=np.array([0, 0, 0.5]),
                  top_normal=np.array([0, 0, 1.0]), thickness_min=0.5, thickness_max=0.5)
    # plane b through (0, 0, 0.5) rising 0.1 per mm along x: 1.5 mm at x = 10
    normal_b = _tilted((-0.1, 0, 1))
    height = wedge_height([layer], np.zeros(3), np.array([0, 0, 1.0]), np.array([0, 0, 0.5]),
                          normal_b)
    assert height == pytest.approx(1.5)


@pytest.mark.slow
def test_branch_3d_layers_are_faced_once_per_run_and_the_part_is_whole():
    # Leaning 50°, past the 45° rule: its bend gets 3-D layers (at exactly 45° it prints
    # planar, support-free at the limit).
    result = plan_job(samples.branch45(lean_deg=50.0), plan_options(HYBRID), part="branch50")
    hybrid = result.hybrid
    runs = [s for s in hybrid.sessions if s["reason"] == "3-D layers' top"]
    assert runs and all(s["passes"] > 0 for s in runs), hybrid.sessions
    assert any("deposited as planar layers" in note for note in result.plan.notes)
    # the published one-session-per-3-D-layer plan took 27 sessions here
    assert hybrid.switches * 3 <= hybrid.naive_switches
    layers = result.layers[0]
    for session in runs:
        run = layers[session["from_layer"]:session["after_layer"] + 1]
        # the run's planar layers share one frame, each standing on the one below (45° rule)
        normals = np.array([layer.top_normal for layer in run if not layer.tilted])
        assert len(normals) >= 2 and np.allclose(normals, normals[0])
        for lower, upper in zip(run, run[1:]):
            if not np.allclose(lower.top_normal, upper.top_normal):
                continue
            rise = upper.section_height - lower.section_height
            reach = rise * math.tan(math.radians(45.0)) + 1e-2
            assert upper.region.difference(lower.region.buffer(reach)).area < 1e-2
    check = hybrid.check
    # nothing of the part is missing (the runs' deposits reach every faced plane) and the
    # facing cut nothing of it
    assert check.gouge_points == 0, check
    # what stock is left lies in the acute corners no 6 mm cutter reaches into
    assert check.uncut_outside_corners == 0, check
    assert any("endmill_6mm,vbit_30deg_6mm" in note for note in result.plan.notes)


def test_layered_support_agrees_with_the_exact_one_on_planar_builds():
    t_block = samples.t_block()
    for direction in ((0, 0, 1), (1, 0, 0), (0, 0, -1)):
        exact = support_volume(t_block, direction)
        assert layered_support_volume(t_block, direction) == pytest.approx(exact, rel=1e-3,
                                                                            abs=1e-6)
    # a ceiling of a hole across the build: curved, sampled
    block = samples.cross_hole_block()
    assert layered_support_volume(block, (0, 0, 1)) == pytest.approx(
        support_volume(block, (0, 0, 1)), rel=1e-2)


@pytest.mark.slow
def test_a_branch_leaning_55_degrees_is_followed_and_saves_most_support():
    # root auto: the plan search turns the part a quarter (less overhang built planar);
    # as modelled, its 3-D layers follow the lean and need less support, so that is chosen
    result = plan_job(samples.branch45(lean_deg=55.0), plan_options(HYBRID), part="branch55")
    hybrid = result.hybrid
    assert any("planned as modelled" in note for note in result.plan.notes)
    assert any(layer.tilted for stack in result.layers.values() for layer in stack)
    # METHODS section 6 reports about 80 % saved on its 45° example
    assert hybrid.support_planar_mm3 > 1000 and hybrid.support_saved >= 0.8, hybrid.to_json()
    assert hybrid.switches * 3 <= hybrid.naive_switches
    assert hybrid.check.gouge_points == 0
    # the decomposition's overhang is for planar layers: the summary says so
    from freecad_conformal.jobs.report import summary_text

    text = summary_text(result)
    assert result.plan.support_area > 0 and "as if built in planar layers" in text
    assert f"support: {hybrid.support_hybrid_mm3:.1f} mm3" in text


def test_corner_zone_depth_is_the_cutter_circle_touching_both_faces():
    from freecad_conformal.geometry.stock import corner_zones

    zones = corner_zones(samples.t_block(), 3.0)
    # the T's two concave edges where the arms meet the stem: 90° wedges, r·cot 45° = r
    assert len(zones) >= 2 and all(depth == pytest.approx(3.0) for _, depth in zones)
    branch = corner_zones(samples.branch45(), 3.0)
    # the 45° wedge under the branch: 3 · cot 22.5° = 7.24 mm
    assert max(depth for _, depth in branch) == pytest.approx(3.0 / math.tan(math.radians(22.5)))
