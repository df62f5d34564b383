"""Hybrid deposition + milling: holes, passes, switching, one program, the material check."""
from __future__ import annotations

import math
import shutil

import numpy as np
import pytest
from shapely.geometry import MultiPolygon, Polygon, box

from freecad_conformal.cli import main
from freecad_conformal.errors import PlanError
from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry import samples
from freecad_conformal.geometry.frames import LayerFrame
from freecad_conformal.geometry.holes import filled, find_holes
from freecad_conformal.geometry.stock import Prism, check_material
from freecad_conformal.geometry.support import support_volume
from freecad_conformal.jobs.options import plan_options
from freecad_conformal.jobs.job import plan_job
from freecad_conformal.paths.milling import (MillTool, contour_passes, drill_passes,
                                             forbidden_region)
from freecad_conformal.jobs.hybrid import mill_tools
from freecad_conformal.paths.hybrid import drill_tool
from freecad_conformal.post.machine import load_machine
from freecad_conformal.post.verify import verify_program
from freecad_conformal.process.library import ToolLibrary

TOOL = MillTool(number=2, id="flat6", diameter=6.0, flute_length=20.0, holder_diameter=20.0,
                holder_length=50.0, feed=300.0, plunge_feed=100.0, rpm=3200.0, stepover=3.0)
HYBRID = {"process": "hybrid", "tool": "laser_powder", "machine": "hybrid_ac",
          "layer_height": 0.5}


def test_holes_found_and_filled_fillets_and_bosses_are_not_holes():
    App, Part = import_freecad()
    block = samples.cross_hole_block()
    blind = block.cut(Part.makeCylinder(2, 5, App.Vector(8, 4, 11), App.Vector(0, 0, 1)))
    edges = [e for e in blind.Edges if e.BoundBox.ZLength > 15.9 and e.BoundBox.XLength < 1e-9
             and e.BoundBox.YLength < 1e-9]
    rounded = blind.makeFillet(1.0, edges[:2])        # concave? no: convex corners, partial
    boss = rounded.fuse(Part.makeCylinder(3, 4, App.Vector(22, 10, 16))).removeSplitter()
    holes = find_holes(boss)
    assert [round(h.diameter, 6) for h in holes] == [6.0, 4.0]
    across, pocket = holes
    assert across.through and np.allclose(np.abs(across.direction), (1, 0, 0))
    assert across.length == pytest.approx(30.0)
    assert pocket.open_ends == (("high",) if pocket.direction[2] > 0 else ("low",))
    solid = filled(samples.cross_hole_block(), find_holes(samples.cross_hole_block()))
    assert solid.Volume == pytest.approx(30 * 20 * 16, rel=1e-5)


def test_support_volume_of_a_t_and_of_a_hole_ceiling():
    App, Part = import_freecad()
    t = Part.makeBox(10, 10, 20, App.Vector(10, 0, 0)).fuse(Part.makeBox(30, 10, 5, App.Vector(0, 0, 20)))
    assert support_volume(t) == pytest.approx(2 * 10 * 10 * 20, rel=1e-6)
    assert support_volume(t, (0, 0, -1)) == pytest.approx(0.0, abs=1e-6)
    # a 6 mm hole across: the ceiling within 45° of the top overhangs; its column stands on
    # the floor: chord from −r·sin45 to r·sin45, area ∫2√(r²−x²)dx
    r = 3.0
    s = r * math.sin(math.pi / 4)
    area = s * math.sqrt(r * r - s * s) * 2 + 2 * r * r * math.asin(s / r)
    assert support_volume(samples.cross_hole_block()) == pytest.approx(30 * area, rel=0.01)


def test_contour_pass_touches_the_wall_and_never_enters_the_part():
    square = MultiPolygon([box(0, 0, 20, 10)])
    forbidden = forbidden_region(square, MultiPolygon(), TOOL)
    passes = contour_passes(forbidden, MultiPolygon([box(-0.5, -0.5, 20.5, 10.5)]),
                            LayerFrame.for_direction((0, 0, 1)), 2.0, TOOL)
    assert len(passes) == 1
    ring = passes[0].points
    assert np.allclose(ring[:, 2], 2.0)
    centre = Polygon(ring[:, :2])
    # the flank reaches the wall everywhere and no further
    distances = [square.distance(centre.exterior.interpolate(f, normalized=True))
                 for f in np.linspace(0, 1, 200)]
    assert min(distances) == pytest.approx(3.0, abs=5e-3) and max(distances) == pytest.approx(3.0, abs=5e-3)
    sweep = passes[0].sweep.region
    assert sweep.intersection(square).area < 1e-3          # no gouge
    assert sweep.covers(box(-0.5, -0.5, 20.5, 10.5).difference(square.geoms[0]).buffer(-1e-3))


def test_a_holder_keeps_the_tool_off_a_wall_it_cannot_reach_past():
    wall = MultiPolygon([box(0, 0, 20, 10)])
    overhead = MultiPolygon([box(0, 0, 8, 10)])           # material above the flutes, one end
    forbidden = forbidden_region(wall, overhead, TOOL)
    passes = contour_passes(forbidden, MultiPolygon([box(-0.5, -0.5, 20.5, 10.5)]),
                            LayerFrame.for_direction((0, 0, 1)), 0.0, TOOL)
    assert len(passes) == 1
    ring = Polygon(passes[0].points[:, :2]).exterior
    points = [ring.interpolate(f, normalized=True) for f in np.linspace(0, 1, 400)]
    assert min(overhead.distance(p) for p in points) == pytest.approx(10.0, abs=1e-2)
    assert min(wall.distance(p) for p in points) == pytest.approx(3.0, abs=1e-2)


def test_drill_refuses_a_tool_wider_than_the_hole_or_too_short():
    with pytest.raises(PlanError, match="wider than a hole"):
        drill_passes(np.zeros(3), np.array([0, 0, -1.0]), 1.0, 5.0, TOOL)
    with pytest.raises(PlanError, match="reaches 20 mm deep"):
        drill_passes(np.zeros(3), np.array([0, 0, -1.0]), 5.0, 25.0, TOOL)
    helix = drill_passes(np.array([1.0, 2.0, 10.0]), np.array([0, 0, -1.0]), 5.0, 8.0, TOOL)[0]
    radial = np.linalg.norm(helix.points[:, :2] - [1.0, 2.0], axis=1)
    assert np.allclose(radial, 2.0) and helix.points[:, 2].min() == pytest.approx(2.0)
    assert helix.sweep.region.area == pytest.approx(math.pi * 25, rel=1e-3)


def test_material_check_finds_stock_left_and_gouges_and_how_deep():
    App, Part = import_freecad()
    part = Part.makeBox(10, 10, 4)
    frame = LayerFrame.for_direction((0, 0, 1))
    deposit = [Prism(frame, box(-1, -1, 11, 11), 0.0, 4.0)]
    trim = Prism(frame, box(-5, -5, 15, 15).difference(box(0, 0, 10, 10)), 0.0, 4.0)
    exact = check_material(part, deposit, [trim])
    assert exact.points > 100 and exact.deposited == pytest.approx(12 * 12 * 4)
    assert exact.uncut_points == exact.gouge_points == 0 and exact.max_deviation == 0
    short = Prism(frame, box(-5, -5, 15, 15).difference(box(-0.3, 0, 10, 10)), 0.0, 4.0)
    left = check_material(part, deposit, [short])
    assert left.uncut_points > 0 and left.max_uncut == 0.25 and left.max_gouge == 0
    deep = Prism(frame, box(-5, -5, 15, 15).difference(box(0.2, 0, 10, 10)), 0.0, 4.0)
    cut = check_material(part, deposit, [deep])
    assert cut.gouge_points > 0 and cut.max_gouge == 0.1 and cut.max_uncut == 0
    # a session mills only what was deposited before it: a layer laid afterwards keeps
    # its stock (the facing of a 3-D layer reaches up into where the next layers go)
    later = [Prism(frame, box(-1, -1, 11, 11), 0.0, 4.0, order=1)]
    untouched = check_material(part, later, [trim])
    assert untouched.max_uncut == 1.0 and untouched.max_gouge == 0


@pytest.mark.slow
def test_cross_hole_block_plans_verifies_and_matches_the_part(tmp_path):
    result = plan_job(samples.cross_hole_block(), plan_options(HYBRID), part="cross_hole_block")
    hybrid = result.hybrid
    assert hybrid.holes_filled and "6 mm" in hybrid.holes_filled[0]
    assert hybrid.support_planar_mm3 > 600 and hybrid.support_hybrid_mm3 == 0
    # one milling session: the block is lower than the cutter's flutes
    assert hybrid.switches == 1 and hybrid.naive_switches == 2 * 32 - 1
    # the deposits hold the filled hole and the stock round the walls: more than the part,
    # and what the mill removes is the difference
    part = samples.cross_hole_block().Volume
    assert hybrid.part_mm3 == pytest.approx(part)
    assert hybrid.deposited_mm3 > part + 6.0 ** 2 * math.pi / 4 * 30.0 * 0.9
    assert hybrid.to_json()["stock_removed_mm3"] == pytest.approx(hybrid.deposited_mm3 - part)
    check = hybrid.check
    # no surface point 0.05 mm out is material, none 0.05 mm in is missing: the hole's
    # wall included (it was filled, then cut)
    assert check.points > 1000 and check.max_deviation == 0
    text = result.post.text
    assert text.count("T2 M6") == 1 and "G43 H2" in text and "M3 S3200" in text
    # the header says the job's time: moves with their corners, and the process switch
    assert f"[{result.time_s:.1f} s])" in text.splitlines()[5]
    assert result.time_s == pytest.approx(hybrid.deposit_s + hybrid.milling_s + hybrid.travel_s
                                          + hybrid.switch_s)
    assert text.count("M68 E0 Q40") == text.count("M68 E0 Q0") > 50
    program = tmp_path / "block.ngc"
    program.write_text(text)
    deviation = verify_program(text, load_machine("hybrid_ac"), result.assembly.toolpath)
    assert deviation.position < 0.01 and deviation.angle < 1e-3, deviation.report()
    if shutil.which("rs274"):
        from freecad_conformal.post.rs274 import canonical_moves

        kinds, _ = canonical_moves(program)
        assert len(kinds) > 500


@pytest.mark.slow
def test_nozzle_hole_is_cut_layer_by_layer_with_the_small_tool():
    options = plan_options({**HYBRID, "mill_tool": "endmill_6mm,drill_0p5"})
    result = plan_job(samples.nozzle(), options, part="nozzle")
    hybrid = result.hybrid
    drills = [s for s in hybrid.sessions if s["passes"] >= 2]
    # 2.5 mm flutes cut 0.5 mm layers in runs of four: five sessions on 10 mm
    assert len(hybrid.sessions) == 5 and len(drills) == 5
    assert hybrid.switches * 3 <= hybrid.naive_switches
    assert hybrid.check.max_deviation < 0.05
    assert result.post.text.count("T3 M6") == 5


def test_hybrid_refuses_a_deposition_tool_as_mill_and_a_material_without_settings():
    with pytest.raises(PlanError, match="takes end mills"):
        plan_job(samples.cross_hole_block(), plan_options({**HYBRID, "mill_tool": "fdm_0p4"}))
    library = ToolLibrary.load()
    with pytest.raises(PlanError, match="no settings for material 'PLA'"):
        mill_tools(["endmill_6mm"], "PLA", library)
    tools = mill_tools(["endmill_6mm", "drill_0p5"], "316L", library)
    assert [(t.number, t.rpm, t.feed) for t in tools] == [(2, 3200, 300), (3, 24000, 30)]
    with pytest.raises(PlanError, match="'vbit_30deg_6mm' is tapered"):
        mill_tools(["vbit_30deg_6mm", "endmill_6mm"], "316L", library)
    with pytest.raises(PlanError, match="'ball_endmill_6mm' is not flat"):
        mill_tools(["ball_endmill_6mm"], "316L", library)
    tools = mill_tools(["endmill_6mm", "vbit_30deg_6mm", "drill_0p5"], "316L", library)
    assert tools[1].tapered and tools[1].stick_out == 30.0 and not tools[0].tapered
    # a V-bit never drills: the hole takes the 0.5 mm mill though the V-bit's tip is finer
    hole = find_holes(samples.nozzle())[0]
    assert drill_tool(hole, tools).id == "drill_0p5"


def test_v_bit_pencil_passes_leave_the_45_degree_branch_within_tolerance(tmp_path):
    options = plan_options({**HYBRID, "mill_tool": "endmill_6mm,vbit_30deg_6mm"})
    result = plan_job(samples.branch45(), options, part="branch45")
    hybrid = result.hybrid
    check = hybrid.check
    # the end mill alone leaves up to 2 mm in the acute corners (tests/.../hybrid_groups);
    # with the V-bit nothing stands proud at any offset checked, and nothing is gouged
    assert check.points > 10000 and check.max_deviation == 0, check
    assert all(counts == (0, 0) for counts in check.by_offset.values())
    last = hybrid.sessions[-1]
    assert "last finishing" in last["reason"]
    text = result.post.text
    assert "T3 M6" in text and "G43 H3" in text
    deviation = verify_program(text, load_machine("hybrid_ac"), result.assembly.toolpath)
    assert deviation.position < 0.01 and deviation.angle < 1e-3, deviation.report()
    if shutil.which("rs274"):
        from freecad_conformal.post.rs274 import canonical_moves

        program = tmp_path / "branch.ngc"
        program.write_text(text)
        assert len(canonical_moves(program)[0]) > 500


def test_pencil_passes_cut_along_the_edges_and_run_up_through_air():
    from freecad_conformal.geometry.concave_edges import concave_edges
    from freecad_conformal.geometry.stock import surface_samples
    from freecad_conformal.paths.pencil import pencil_passes

    branch = samples.branch45()
    vbit = mill_tools(["endmill_6mm", "vbit_30deg_6mm"], "316L", ToolLibrary.load())[1]
    notes: list[str] = []
    passes = pencil_passes(branch, [vbit], *surface_samples(branch), notes)
    # four straight concave edges: two 45° wedges (two passes each), two 90° (four each)
    assert len(concave_edges(branch)) == 4 and len(passes) == 12 and not notes
    for cut in passes:
        along = cut.points[-1] - cut.points[0]
        along /= np.linalg.norm(along)
        assert cut.lead == 1 and len(cut.points) == 4
        assert abs(float(cut.axis @ along)) < 1e-9          # the cutter square to the edge
        # the cutting stretch spans an edge of the branch (10 mm wide, 7.07 mm at its foot)
        # and a tool radius and a millimetre beyond each end, no more
        span = float(np.linalg.norm(cut.points[2] - cut.points[1]))
        assert any(span == pytest.approx(length + 2 * (3.0 + 1.0), abs=1e-6)
                   for length in (10.0, 10.0 / math.sqrt(2.0)))


def test_ball_end_mill_finishes_the_dome_the_flat_one_leaves_stepped():
    dome = samples.domed_cylinder()
    flat = plan_job(dome, plan_options(HYBRID), part="dome")
    # planar layers leave steps on the dome a flat end mill cannot take off (a quarter of
    # a 0.5 mm layer and more), and the plan says which tool would
    assert flat.hybrid.check.max_uncut >= 0.25
    assert any("endmill_6mm,ball_endmill_6mm" in note for note in flat.plan.notes)
    # the top slab is deposited whole: nothing of the part is missing under the dome's top
    assert flat.hybrid.check.gouge_points == 0
    options = plan_options({**HYBRID, "mill_tool": "endmill_6mm,ball_endmill_6mm"})
    result = plan_job(dome, options, part="dome")
    check = result.hybrid.check
    assert check.points > 1000 and all(c == (0, 0) for c in check.by_offset.values()), check
    assert "T3 M6" in result.post.text
    deviation = verify_program(result.post.text, load_machine("hybrid_ac"),
                               result.assembly.toolpath)
    assert deviation.position < 0.01 and deviation.angle < 1e-3, deviation.report()


def test_plan_command_takes_process_and_mill_tool(tmp_path, capsys):
    out = tmp_path / "block.ngc"
    code = main(["plan", "cross_hole_block", "--process", "hybrid", "--tool", "laser_powder",
                 "--machine", "hybrid_ac", "--layer-height", "0.5", "--no-material-check",
                 "-o", str(out), "--report", str(tmp_path / "r.json")])
    assert code == 0
    printed = capsys.readouterr().out
    assert "hybrid: deposit" in printed and "switches" in printed
    import json

    report = json.loads((tmp_path / "r.json").read_text())
    assert report["hybrid"]["switches"] == 1 and report["hybrid"]["material_check"] is None
    assert report["settings"]["process"]["value"] == "hybrid"


@pytest.mark.slow
def test_auto_root_follows_the_search_that_turns_a_t_upside_down():
    # as modelled the T's arms overhang (support under them); the plan search builds it
    # upside down, which the hybrid plan follows: no support at all
    result = plan_job(samples.t_block(), plan_options({**HYBRID, "material_check": False}))
    hybrid = result.hybrid
    assert hybrid.support_planar_mm3 > 1000
    assert hybrid.support_hybrid_mm3 == 0 and hybrid.support_saved == 1.0
    assert result.subparts[0].direction @ np.array([0.0, 0.0, 1.0]) == pytest.approx(1.0)
    assert not any("not followed" in note for note in result.plan.notes)


@pytest.mark.slow
def test_job_object_computes_a_hybrid_plan_mapped_back_onto_the_part():
    from freecad_conformal.gui.path_display import frame_matrices, to_part_frame
    from freecad_conformal.objects.job_feature import compute_job
    from freecad_conformal.objects.toolpath_feature import toolpath_from_bytes
    from freecad_conformal.settings.plan import PLAN_SETTINGS
    from freecad_conformal.settings.schema import defaults
    from freecad_conformal.toolpath import KINDS

    App, Part = import_freecad()
    shape = samples.t_block()                       # the search builds it upside down
    values = dict(defaults(PLAN_SETTINGS), **HYBRID, material_check=False)
    result = compute_job({"brep": shape.exportBrepToString(), "part": "t", "values": values},
                         lambda *_: None)
    assert "hybrid: deposit" in result["summary"] and "T2 M6" in result["gcode"]
    toolpath = toolpath_from_bytes(result["toolpath"])
    matrices = frame_matrices(result["frame_subparts"], result["frames"])
    on_part = to_part_frame(toolpath.points, toolpath.segment_index,
                            result["segment_subparts"], matrices)
    deposit = np.flatnonzero(toolpath.kind[toolpath.segment_index] == KINDS.index("deposit"))
    sample = deposit[:: max(1, len(deposit) // 100)]
    inside = np.mean([shape.isInside(App.Vector(*map(float, p)), 0.6, True) for p in on_part[sample]])
    assert inside > 0.95
