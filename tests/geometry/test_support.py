"""Support printed under what a plan leaves overhanging (`plan --support`, paths/support.py)."""
from __future__ import annotations

import json

import numpy as np
import pytest

from freecad_conformal.jobs.options import plan_options
from freecad_conformal.paths.support import (CONTACT_LAYERS, SUPPORT_ROLES, SupportSettings,
                                             stack_support)

LAYER = 0.2


def _shelf(App, Part, lower_shelf: bool = False):
    """A 10 x 10 x 20 mm post with a 20 mm shelf at its top (3 mm thick, along +X); with
    `lower_shelf`, a second one reaching half as far (x 10..20) from z 8 to 10, so columns
    under the top shelf's near half land on it."""
    part = Part.makeBox(10, 10, 20).fuse(Part.makeBox(30, 10, 3, App.Vector(0, 0, 20)))
    if lower_shelf:
        part = part.fuse(Part.makeBox(20, 10, 2, App.Vector(0, 0, 8)))
    return part.removeSplitter()


def _planned(shape, **values):
    from freecad_conformal.jobs.plan import plan_additive

    given = {"root": (0.0, 0.0, 1.0), "decompose": False, "layer_height": LAYER, **values}
    return plan_additive(shape, plan_options(given), part="shelf")


def _support_points(result, step: float = 0.25) -> np.ndarray:
    """Points along the support's deposits, at most `step` apart (a line has only its ends)."""
    found = [np.zeros((0, 3))]
    for path in result.assembly.paths:
        if path.role not in SUPPORT_ROLES:
            continue
        for a, b in zip(path.points, path.points[1:]):
            count = max(1, int(np.ceil(np.linalg.norm(b - a) / step)))
            found.append(a + np.linspace(0.0, 1.0, count + 1)[:, None] * (b - a))
    return np.vstack(found)


def test_support_stands_under_the_shelf_and_nowhere_else(App, Part):
    """The shelf leaves 200 mm² over air along +Z: with --support, columns from the platform
    to one contact layer under the shelf, beside the post (half a bead clear of it) and
    within the shelf's outline; without it, none, and the summary says the G-code lays that
    area over air."""
    shelf = _shelf(App, Part)
    bare = _planned(shelf)
    result = _planned(shelf, support=True)
    assert not len(_support_points(bare)) and bare.support_volume == 0.0
    assert "does not print" in bare.summary() and "--support prints it" in bare.summary()
    points = _support_points(result)
    x, y, z = points.T
    half_bead = 0.5 * result.bead_width
    assert x.min() >= 10.0 + half_bead - 1e-6 and x.max() <= 30.0 + 1e-6
    assert y.min() >= -1e-6 and y.max() <= 10.0 + 1e-6
    assert z.min() <= LAYER + 1e-6          # on the platform
    assert z.max() <= 20.0 - CONTACT_LAYERS * LAYER + 1e-6
    assert z.max() >= 20.0 - (CONTACT_LAYERS + 1) * LAYER - 1e-6
    # The interface is the solid top of the columns; the sparse lines below it.
    interface = np.vstack([p.points for p in result.assembly.paths
                           if p.role == "support_interface"])
    assert interface[:, 2].min() > 20.0 - 5 * LAYER
    # It is part of the material, and both the summary and the report say how much.
    assert result.support_volume > 0
    assert result.material_volume == pytest.approx(bare.material_volume + result.support_volume,
                                                   rel=0.02)
    assert "printed on" in result.summary() and "cm3 of support" in result.summary()


def test_support_stops_where_it_lands_on_the_part(App, Part):
    """A lower shelf (x 10..20, z 8..10) under the top one's near half: columns there stand
    on it, one contact layer above it, and none runs through it; the far half's columns and
    the lower shelf's own stand on the platform."""
    result = _planned(_shelf(App, Part, lower_shelf=True), support=True)
    assert len(result.layers) == 1          # one solid, the lower shelf joined to the post
    points = _support_points(result)
    near = points[(points[:, 0] > 10.5) & (points[:, 0] < 19.5)]
    far = points[points[:, 0] > 20.5]
    assert len(near) and len(far)
    through = near[(near[:, 2] > 8.0 - CONTACT_LAYERS * LAYER + 1e-6)
                   & (near[:, 2] < 10.0 + (CONTACT_LAYERS + 1) * LAYER - 1e-6)]
    assert not len(through)
    assert near[near[:, 2] > 10.0][:, 2].min() <= 10.0 + (CONTACT_LAYERS + 2) * LAYER + 1e-6
    assert near[:, 2].min() <= LAYER + 1e-6 and far[:, 2].min() <= LAYER + 1e-6
    assert far[:, 2].max() >= 19.0


def test_columns_of_a_sub_part_resting_on_its_parent_are_dropped_and_counted(App, Part):
    """Resting on a parent, the sub-part's layers do not know what lies below its base: the
    shelf's columns, which all reach it, are dropped and their area counted; a column that
    lands on the sub-part's own step is kept."""
    shelf = _planned(_shelf(App, Part))
    layers = shelf.layers[0]
    width = shelf.bead_width
    on = stack_support(layers, SupportSettings(enabled=True), width, on_platform=True)
    off = stack_support(layers, SupportSettings(enabled=True), width, on_platform=False)
    assert not on.empty and on.dropped_area == 0.0
    assert off.empty and 150.0 < off.dropped_area < 200.0
    stepped = _planned(_shelf(App, Part, lower_shelf=True))
    kept = stack_support(stepped.layers[0], SupportSettings(enabled=True), width,
                         on_platform=False)
    assert not kept.empty and kept.dropped_area > 0.0
    for base, interface in zip(kept.base, kept.interface):
        if not (base.is_empty and interface.is_empty):
            columns = base.union(interface).bounds
            assert columns[0] >= 10.0 and columns[2] <= 20.0      # only those on the shelf
    assert stack_support(layers, SupportSettings(enabled=False), width, True).empty


def test_support_in_the_way_of_a_later_sub_part_is_not_printed(App, Part):
    """A block built after the shelf along +X from beside the post: the tool's body reaches
    over the post into the columns under the shelf, so the shelf's support is left out
    (support stays until it is broken away); built along -X it points away and the
    support is kept."""
    from freecad_conformal.decomposition.build_order import tool_envelope
    from freecad_conformal.decomposition.subparts import BuildPlan, SubPart
    from freecad_conformal.paths.assemble import PathSettings
    from freecad_conformal.paths.support_plan import supports_of

    shelf = _planned(_shelf(App, Part))
    envelope = tool_envelope("fdm_0p4")
    block = Part.makeBox(4, 10, 5, App.Vector(-14, 0, 5))
    settings = PathSettings()
    settings.support = SupportSettings(enabled=True)
    settings.fill.bead_width = shelf.bead_width
    for direction, blocked in ((np.array([1.0, 0.0, 0.0]), True),
                               (np.array([-1.0, 0.0, 0.0]), False)):
        plan = BuildPlan([SubPart(0, shelf.plan.subparts[0].shape, np.array([0.0, 0.0, 1.0]),
                                  overhang_area=200.0),
                          SubPart(1, block, direction)], order=[0, 1])
        sideways = shelf.layers[0][0]
        found, notes = supports_of(plan, {0: shelf.layers[0], 1: [sideways]},
                                   settings.support, settings.fill.bead_width, envelope)
        assert (0 not in found) is blocked, notes
        assert any("building sub-part 1" in note for note in notes) is blocked


def test_report_names_the_support_printed(App, Part, tmp_path):
    from freecad_conformal.cli import main

    path = tmp_path / "shelf.brep"
    _shelf(App, Part).exportBrep(str(path))
    out = tmp_path / "shelf.ngc"
    assert main(["plan", str(path), "--root", "0,0,1", "--no-decompose", "--support",
                 "-o", str(out), "--report", str(tmp_path / "plan.json")]) == 0
    data = json.loads((tmp_path / "plan.json").read_text())
    assert data["support_mm3"] > 0 and data["residual_overhang_mm2"] == pytest.approx(200.0)
    assert data["settings"]["support"]["value"] is True
    assert data["material_mm3"] == pytest.approx(sum(s["material_mm3"] for s in data["sub_parts"]))


def test_a_hybrid_plan_refuses_support_before_any_geometry_work(Part):
    """The hybrid job lays its own paths and prints no support: asked for some, it says so
    rather than ignore the setting."""
    from freecad_conformal.errors import PlanError
    from freecad_conformal.jobs.hybrid import plan_hybrid

    options = plan_options({"support": True, "process": "hybrid", "tool": "laser_powder",
                            "machine": "hybrid_ac", "mill_tool": "endmill_6mm"})
    with pytest.raises(PlanError, match=r"support \(--support / PrintSupport\)"):
        plan_hybrid(Part.makeBox(10, 10, 10), options)


def test_the_preview_draws_support_in_its_own_colour(App, Part):
    """Support is drawn dark grey with a legend entry, not in its sub-part's colour: a user
    sees what breaks away."""
    import io

    from PIL import Image

    from freecad_conformal.paths.preview import SUPPORT, render_png

    def grey(result) -> int:
        out = io.BytesIO()
        render_png(result.assembly, out, "shelf")
        return list(Image.open(io.BytesIO(out.getvalue())).convert("RGB").getdata()).count(SUPPORT)

    # A few grey pixels are the text's anti-aliasing; the columns are thousands.
    assert grey(_planned(_shelf(App, Part), support=True)) > 20 * grey(_planned(_shelf(App, Part)))


def test_support_that_would_stand_in_another_sub_part_is_not_printed(App, Part):
    """A block built before the shelf, standing where the shelf's columns would go: they
    would be printed into it, so the shelf's support is left out with a note; the block
    set beside the shelf instead leaves it."""
    from freecad_conformal.decomposition.build_order import tool_envelope
    from freecad_conformal.decomposition.subparts import BuildPlan, SubPart
    from freecad_conformal.paths.assemble import PathSettings
    from freecad_conformal.paths.support_plan import supports_of

    shelf = _planned(_shelf(App, Part))
    settings = PathSettings()
    settings.support = SupportSettings(enabled=True)
    settings.fill.bead_width = shelf.bead_width
    up = np.array([0.0, 0.0, 1.0])
    for corner, inside in ((App.Vector(22, 2, 0), True), (App.Vector(40, 2, 0), False)):
        block = Part.makeBox(5, 5, 8, corner)
        plan = BuildPlan([SubPart(0, block, up),
                          SubPart(1, shelf.plan.subparts[0].shape, up, overhang_area=200.0)],
                         order=[0, 1])
        found, notes = supports_of(plan, {0: shelf.layers[0][:40], 1: shelf.layers[0]},
                                   settings.support, settings.fill.bead_width,
                                   tool_envelope("fdm_0p4"))
        assert (1 not in found) is inside, notes
        assert any("stand in sub-part 0" in note for note in notes) is inside


def test_a_job_in_freecad_prints_the_support_the_command_line_prints(App, Part):
    """The Job object's PrintSupport reaches the plan as `--support` does: the same G-code."""
    from freecad_conformal.jobs.job import plan_job
    from freecad_conformal.objects.computed import shape_to_bytes
    from freecad_conformal.objects.job_feature import compute_job
    from freecad_conformal.settings.plan import PLAN_SETTINGS
    from freecad_conformal.settings.schema import defaults

    shelf = _shelf(App, Part)
    values = {**defaults(PLAN_SETTINGS), "support": True, "root": (0.0, 0.0, 1.0),
              "decompose": False}
    job = compute_job({"brep": shape_to_bytes(shelf), "part": "shelf", "values": values},
                      lambda *_: None)
    command_line = plan_job(shelf, plan_options(values), part="shelf")
    assert command_line.support_volume > 0
    assert job["gcode"] == command_line.post.text
    # The 3D view draws support apart: the job names the segments that print it, those of
    # the support paths and no others.
    from freecad_conformal.objects.toolpath_feature import toolpath_from_bytes
    from freecad_conformal.paths.support import SUPPORT_ROLES

    toolpath = toolpath_from_bytes(job["toolpath"])
    deposits = [k for k in range(toolpath.segment_count) if toolpath.kind_name(k) != "travel"]
    roles = [p.role for p in command_line.assembly.paths]
    assert len(deposits) == len(roles)
    expected = [k for k, role in zip(deposits, roles) if role in SUPPORT_ROLES]
    assert expected and job["support_segments"] == expected


def _gate(App, Part):
    """Two 10 x 10 x 20 mm pillars 20 mm apart under a 4 mm beam that reaches 15 mm past
    the second one: a bridge (x 10..30) and a cantilever (x 40..55) at z = 20."""
    V = App.Vector
    return Part.makeBox(10, 10, 20).fuse([Part.makeBox(10, 10, 20, V(30, 0, 0)),
                                          Part.makeBox(55, 10, 4, V(0, 0, 20))]).removeSplitter()


def test_a_bridge_from_pillar_to_pillar_gets_no_support_a_cantilever_does(App, Part):
    """As PrusaSlicer by default ("Don't support bridges"): the beam between the pillars is
    laid from one to the other over the gap, without columns; the end past the second
    pillar, anchored on one side only, stands on columns; `support_bridges` supports both.
    The summary's notes say what was bridged."""
    gate = _gate(App, Part)
    result = _planned(gate, support=True)
    points = _support_points(result)
    assert len(points) and points[:, 0].min() >= 40.0        # under the cantilever only
    assert "laid as bridges from wall to wall" in result.summary()
    assert 150.0 < result.assembly.bridged_area <= 200.0     # the 20 x 10 mm beam's underside
    both = _support_points(_planned(gate, support=True, support_bridges=True))
    assert len(both[(both[:, 0] > 11.0) & (both[:, 0] < 29.0)])
    assert len(both[both[:, 0] > 41.0])
    # The bridge's beads run from pillar to pillar (along x), not across the 10 mm width
    # with both ends over air.
    first = [p for p in result.assembly.paths if p.role == "bridge_infill"
             and abs(p.points[0, 2] - 20.0 - LAYER) < 1e-6
             and 10.0 < p.points[:, 0].mean() < 30.0]
    assert first
    steps = np.vstack([np.diff(p.points, axis=0) for p in first])
    longest = steps[np.argmax(np.linalg.norm(steps, axis=1))]
    assert abs(longest[0]) > 15.0 and abs(longest[1]) < 1e-6


def test_columns_standing_on_the_part_have_a_solid_foot_those_on_the_platform_none(App, Part):
    """PrusaSlicer's bottom interface (as many layers as on top by default): the columns on
    the lower shelf (top z = 10) start with solid layers above their contact gap; those on
    the platform start sparse; `support_bottom_interface_layers` 0 leaves the foot sparse."""
    shelf = _shelf(App, Part, lower_shelf=True)

    def interface_points(**values):
        result = _planned(shelf, support=True, **values)
        return np.vstack([p.points for p in result.assembly.paths
                          if p.role == "support_interface"] or [np.zeros((0, 3))])

    first_column = 10.0 + (CONTACT_LAYERS + 1) * LAYER        # the first layer on the shelf
    for values, layers in (({}, 3), ({"support_bottom_interface_layers": 1}, 1),
                           ({"support_bottom_interface_layers": 0}, 0)):
        points = interface_points(**values)
        # (the columns under the lower shelf have their solid top at z 7.4-7.8)
        foot = points[(points[:, 2] > 10.0) & (points[:, 2] < 15.0) & (points[:, 0] > 10.5)
                      & (points[:, 0] < 19.5)]
        assert len(np.unique(np.round(foot[:, 2], 6))) == layers, values
        if layers:
            assert foot[:, 2].min() == pytest.approx(first_column, abs=1e-6)
            assert foot[:, 2].max() == pytest.approx(first_column + (layers - 1) * LAYER,
                                                     abs=1e-6)
        # the far half stands on the platform: solid only at its top, under the shelf
        assert not len(points[(points[:, 2] < 15.0) & (points[:, 0] > 20.5)])


@pytest.mark.parametrize("gap", [2.5, 1.0])
def test_support_lines_leave_the_gap_asked_between_them_as_prusaslicer(gap):
    """PrusaSlicer's "pattern spacing" is the gap between support lines: at its default
    2.5 mm they lie 2.5 mm plus a line's spacing apart. Ours laid them 2.5 mm apart, 14 %
    more support than the peer at the same setting."""
    from shapely.geometry import MultiPolygon, box

    from freecad_conformal.paths.bead import bead_spacing
    from freecad_conformal.paths.support import support_paths

    width, model = 0.45, "rounded"
    paths = support_paths(MultiPolygon([box(0, 0, 30, 30)]), MultiPolygon(),
                          SupportSettings(enabled=True, spacing=gap), width, LAYER, model)
    points = np.vstack([p.points for p in paths])
    # Rows along x: their y values, one per row, evenly apart.
    rows = np.unique(np.round(points[:, 1], 6))
    pitch = np.diff(rows)
    assert len(rows) > 5
    np.testing.assert_allclose(pitch, gap + bead_spacing(width, LAYER, model), rtol=1e-6)
