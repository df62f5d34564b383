"""The plan command end to end, and bad input that must leave no output."""
from __future__ import annotations

import re

import numpy as np
import pytest

from freecad_conformal.cli import main
from freecad_conformal.errors import PlanError
from freecad_conformal.geometry import samples
from freecad_conformal.jobs.plan import PlanOptions, run_job, single_plan
from freecad_conformal.decomposition.subparts import BuildPlan, SubPart


@pytest.mark.slow
def test_plan_command_writes_gcode_preview_and_summary(tmp_path, capsys):
    out = tmp_path / "jack.ngc"
    summary = tmp_path / "jack.txt"
    code = main(["plan", "jack", "--machine", "trunnion_ac", "--tool", "fdm_0p4", "--layer", "0.4",
                 "--jerk", "4", "-o", str(out), "--summary", str(summary),
                 "--toolpath", str(tmp_path / "jack.npz")])
    assert code == 0
    printed = capsys.readouterr().out
    for word in ("sub-part", "layers:", "material:", "estimated time:", "support:"):
        assert word in printed
    text = out.read_text()
    assert "(machine: Table-table A/C trunnion [trunnion_ac])" in text
    assert text.count("M64 P0") == text.count("M65 P0") > 100
    assert (tmp_path / "jack.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert summary.read_text() == printed
    assert (tmp_path / "jack.npz").stat().st_size > 0
    # The saved toolpath, posted on its own, says the plan's time (the jerk it used).
    header = next(line for line in text.splitlines() if line.startswith("(estimated time:"))
    again = tmp_path / "again.ngc"
    assert main(["post", str(tmp_path / "jack.npz"), "--machine", "trunnion_ac",
                 "-o", str(again)]) == 0
    assert header in again.read_text().splitlines()


@pytest.mark.slow
def test_summary_figures_agree_with_the_toolpath():
    shape = samples.jack()
    result = run_job(shape, single_plan(shape), PlanOptions(), part="jack")
    summary = result.assembly.toolpath.summary()
    assert result.material_volume == pytest.approx(summary.material_volume, rel=1e-9)
    assert result.deposit_length == pytest.approx(summary.length_by_kind["deposit"], rel=1e-9)
    # trapezoids with jerk-limited corners are slower than one trapezoid per polyline
    assert result.time_s > summary.time_s * 0.9
    # the program's header says the summary's time, not the toolpath's own estimate
    seconds = round(result.time_s)
    assert (f"(estimated time: {seconds // 3600}:{seconds // 60 % 60:02d}:{seconds % 60:02d} "
            f"[{result.time_s:.1f} s])") in result.post.text.splitlines()[:8]
    assert result.post.time_s == result.time_s
    # 2 perimeters of 0.4 mm, 20 % infill, 3 solid layers: well under the solid volume
    assert 0.3 * shape.Volume < result.material_volume < 0.8 * shape.Volume


@pytest.mark.parametrize("arguments, message", [
    (["--layer", "0"], "layer height (--layer-height / LayerHeight) must be > 0 mm, got 0"),
    (["--layer-height", "-0.2"], "layer height (--layer-height / LayerHeight) must be > 0 mm"),
    (["--layer", "100"], "larger than the part"),
    (["--bead-width", "-0.4"], "bead width (--bead-width / BeadWidth) must be > 0 mm, got -0.4"),
    (["--bead-width", "100"], "bead width 100 mm is larger than the part"),
    (["--tool", "no_such_tool"], "no tool 'no_such_tool' in the library"),
    (["--tool", "endmill_6mm"], "is a end_mill"),
    (["--machine", "no_such_machine"], "unknown machine 'no_such_machine'"),
    (["--root", "1,0"], "root direction (--root / Root) must be auto, as placed or a "
                        "direction x,y,z (finite, not the zero vector), got '1,0': not three "
                        "numbers"),
    (["--root", "0,0,0"], "got '0,0,0'"),
    (["--layer-height", "5mm"], "layer height (--layer-height / LayerHeight) 5 mm is taller "
                                "than the bead is wide (0.4 mm, tool fdm_0p4)"),
    (["--layer-mode", "adaptive", "--layer-max", "0.6"],
     "maximum layer height (--layer-max / LayerMax) 0.6 mm is taller than the bead is wide"),
])
def test_bad_input_writes_nothing(tmp_path, capsys, arguments, message):
    out = tmp_path / "x.ngc"
    code = main(["plan", "jack", "-o", str(out), *arguments])
    assert code == 1
    assert message in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_a_machine_that_cannot_reach_a_direction_is_refused(tmp_path):
    shape = samples.jack()
    plan = BuildPlan([SubPart(0, shape, np.array([1.0, 0.0, 0.0]))], order=[0])
    with pytest.raises(PlanError, match=r"machine 'Plain 3-axis' cannot point the tool along "
                                        r"sub-part 0's build direction \[1.0, 0.0, 0.0\]"):
        run_job(shape, plan, PlanOptions(machine="three_axis"), part="jack")


def test_a_part_modelled_off_the_platform_is_moved_over_its_centre(Part):
    """A chair modelled at x = 1000 failed "X outside [-300, 300]" after minutes of work."""
    from freecad_conformal.freecad_env import import_freecad
    from freecad_conformal.jobs.plan import machine_plan

    App, _ = import_freecad()
    far = Part.makeBox(20, 20, 10, App.Vector(1000, -700, 5))
    placed, plan = machine_plan(far, PlanOptions(decompose=False))
    centre = placed.BoundBox.Center
    assert abs(centre.x) < 1e-6 and abs(centre.y) < 1e-6
    assert plan.notes[0].startswith("part modelled where, turned to be built, it could leave "
                                    "the machine's X/Y travel: moved by (-1010.000, +690.000, "
                                    "+0.000) mm")


def test_the_search_measures_the_centred_part_and_its_choice_says_so(App):
    """The plan choice centres a part modelled off the platform before its search, so every
    candidate is measured and placed from that one copy; the chosen plan still says the
    part was moved, once."""
    from freecad_conformal.jobs.plan import check_options, choose_plan

    far = samples.l_block()
    far.translate(App.Vector(800, -600, 0))
    options = PlanOptions()
    choice = choose_plan(far, options, check_options(far, options))
    moved = [note for note in choice.plan.notes if note.startswith("part modelled where")]
    assert len(moved) == 1 and "moved by (-8" in moved[0]
    assert len(choice.candidates) > 1
    for candidate in choice.candidates:
        centre = candidate.placed.BoundBox.Center
        assert abs(centre.x) < 60 and abs(centre.y) < 60


def test_a_part_that_could_leave_the_travel_once_turned_is_centred(Part):
    """Inside the travel as modelled (y 265..285), but 60 mm tall: on its side it would
    reach y = 305 (the Pump_Nut reached 300.3 and the post refused it)."""
    from freecad_conformal.freecad_env import import_freecad
    from freecad_conformal.jobs.plan import centred_if_off_platform
    from freecad_conformal.post.machine import load_machine

    App, _ = import_freecad()
    machine = load_machine("trunnion_ac")
    tall = Part.makeBox(20, 20, 60, App.Vector(50, 265, -30))
    moved, note = centred_if_off_platform(tall, machine)
    assert note is not None and "moved by (-60.000, -275.000, +0.000) mm" in note
    assert moved.BoundBox.Center.y == pytest.approx(0.0, abs=1e-9)
    small = Part.makeBox(20, 20, 10, App.Vector(50, 200, 0))
    assert centred_if_off_platform(small, machine) == (small, None)


def test_a_part_that_fits_no_orientation_is_refused_before_any_geometry_work(Part, monkeypatch):
    from freecad_conformal.jobs import plan as jobs_plan

    def must_not_run(*_args, **_kwargs):
        raise AssertionError("geometry work started on a part that cannot fit")

    monkeypatch.setattr(jobs_plan, "machine_plan", must_not_run)
    with pytest.raises(PlanError, match=r"cannot fit Table-table A/C trunnion in any orientation"):
        jobs_plan.plan_additive(Part.makeBox(1e6, 1e6, 1e6), PlanOptions())


def test_a_bar_longer_than_the_travel_is_refused_before_its_layers(Part, monkeypatch):
    """A 900 mm bar fits the trunnion's 600 mm cube of travel diagonally (so `check_fits`
    lets it through), but no plan lays it out so: it was sliced, filled and posted for 13 s
    before the post refused its first point. Each way to build it is refused once laid out,
    and the error says so once, with the bar's size and the axis it leaves."""
    from freecad_conformal.errors import BeyondTravelError
    from freecad_conformal.jobs import plan as jobs_plan

    def must_not_run(*_args, **_kwargs):
        raise AssertionError("layers were planned for a part that cannot be built")

    monkeypatch.setattr(jobs_plan, "run_job", must_not_run)
    with pytest.raises(BeyondTravelError) as caught:
        jobs_plan.plan_additive(Part.makeBox(900, 50, 20), PlanOptions())
    message = str(caught.value)
    assert message.startswith("the part does not fit the travel of Table-table A/C trunnion in "
                              "any of the ")
    assert "solid 1, 900.0 x 50.0 x 20.0 mm as laid out over the platform's centre" in message
    assert "X = -448.0036 mm at point 0 is outside the limits [-300.0, 300.0]" in message
    assert message.count("does not fit") == 1
    # A coarse child's refusal crosses its pipe as a pickle (it broke the answer before).
    import pickle
    assert str(pickle.loads(pickle.dumps(caught.value))) == message
    with pytest.raises(BeyondTravelError, match=r"Z = 898\.0036 mm at point \d is outside the "
                                                r"limits \[-250\.0, 350\.0\]"):
        jobs_plan.machine_plan(Part.makeBox(20, 50, 900), PlanOptions(decompose=False))


def test_a_bar_wider_than_the_travel_is_turned_to_fit_it(Part):
    """650 mm of bar on 600 mm of X travel: laid straight the post refused its first point;
    turned by 27° about the vertical it stands inside the 600 x 600 mm travel."""
    from freecad_conformal.jobs.plan import machine_plan

    _, plan = machine_plan(Part.makeBox(650, 40, 15), PlanOptions(decompose=False))
    assert any(note.startswith("the plan turned by 27 deg about the vertical") for note in plan.notes)
    (sub,) = plan.subparts
    assert np.allclose(sub.build_direction, (0.0, 0.0, 1.0))
    corners = np.array([tuple(v.Point) for v in sub.shape.Vertexes])
    assert np.all(np.abs(corners[:, :2]) <= 300.0)
    assert corners[:, 0].max() - corners[:, 0].min() > 580.0     # turned, not shrunk
    assert sub.shape.Volume == pytest.approx(650 * 40 * 15)


@pytest.mark.slow
def test_a_bar_turned_to_fit_the_travel_is_posted(Part):
    from freecad_conformal.jobs.plan import plan_additive

    result = plan_additive(Part.makeBox(650, 40, 15), PlanOptions())
    x, y = (result.post.values[:, result.post.names.index(name)] for name in ("X", "Y"))
    assert np.abs(x).max() <= 300.0 and np.abs(y).max() <= 300.0
    assert x.max() - x.min() > 500.0


def test_a_machine_without_a_platform_is_refused_before_any_geometry_work(tmp_path, capsys,
                                                                          monkeypatch):
    """The mandrel's pivot is its axis: a part set down there left the X travel only when
    posted (X = -24.4 mm on the bracket)."""
    from freecad_conformal.jobs import plan as jobs_plan

    def must_not_run(*_args, **_kwargs):
        raise AssertionError("geometry work started on a machine without a platform")

    monkeypatch.setattr(jobs_plan, "machine_plan", must_not_run)
    out = tmp_path / "b.ngc"
    assert main(["plan", "bracket", "--machine", "rotary_mandrel", "-o", str(out)]) == 1
    assert re.search(r"error: machine '4-axis rotary mandrel \(A about X\)' .* has no build "
                     r"platform.*`plan --mandrel`", capsys.readouterr().err)
    assert list(tmp_path.iterdir()) == []


def test_plan_report_json_names_every_setting_it_used(tmp_path):
    import json

    from freecad_conformal.settings.plan import PLAN_SETTINGS

    report = tmp_path / "t.json"
    assert main(["plan", "t_block", "-o", str(tmp_path / "t.ngc"), "--report", str(report),
                 "--layer-height", "0.3", "--infill", "15", "--solid-infill-speed", "25"]) == 0
    data = json.loads(report.read_text())
    assert data["format"] == "conformal.plan/1"
    assert set(data["settings"]) == {s.key for s in PLAN_SETTINGS} | {"acceleration",
                                                                       "small_perimeter_length"}
    # Every speed as printed: given, or derived (the material's feed, the solid infill's).
    speeds = data["settings"]
    assert speeds["solid_infill_speed"] == {"value": 25.0, "unit": "mm/s", "used": 25.0}
    assert speeds["bridge_infill_speed"]["value"] is None
    assert speeds["bridge_infill_speed"]["used"] == 25.0
    assert speeds["perimeter_speed"]["used"] > 0 and "derived" in speeds["perimeter_speed"]
    assert speeds["acceleration"]["value"] > 0 and speeds["acceleration"]["unit"] == "mm/s^2"
    assert data["settings"]["layer_height"] == {"value": 0.3, "unit": "mm"}
    assert data["settings"]["infill"]["value"] == 15.0
    assert data["residual_overhang_mm2"] == 0.0 and len(data["sub_parts"]) == 1
    assert data["residual_overhang_reason"] is None
    assert data["material_mm3"] == pytest.approx(sum(s["material_mm3"] for s in data["sub_parts"]))
    assert sum(s["volume_mm3"] for s in data["sub_parts"]) == pytest.approx(samples.t_block().Volume)


def test_layers_as_tall_as_the_bead_is_wide_are_the_most_a_plan_takes(Part):
    """A bead cannot be taller than it is wide (PrusaSlicer refuses layers above the nozzle
    diameter): up to the bead width is planned, beyond it refused (a defaulted maximum of
    adaptive layers, 1.5 x, is taken down to the bead: the test below)."""
    from freecad_conformal.jobs.plan import check_options
    from freecad_conformal.layers.model import LayerSettings

    box = Part.makeBox(20, 20, 20)
    width = check_options(box, PlanOptions())[2]
    for layers in (LayerSettings(thickness=width), LayerSettings(mode="adaptive", thickness=width)):
        assert check_options(box, PlanOptions(layers=layers))[2] == width
    for layers in (LayerSettings(thickness=1.05 * width),
                   LayerSettings(mode="adaptive", thickness=0.5 * width,
                                 max_thickness=1.05 * width)):
        with pytest.raises(PlanError, match="taller than the bead is wide"):
            check_options(box, PlanOptions(layers=layers))


def test_adaptive_layers_left_to_their_default_maximum_are_no_taller_than_the_bead(Part):
    """0.3 mm adaptive layers of 0.4 mm beads: the default maximum (1.5 x, 0.45 mm) would
    let the cone's steep flank take layers taller than the bead is wide; it is taken down
    to the bead width, and a minimum set above the bead is refused."""
    from freecad_conformal.jobs.plan import check_options, plan_additive
    from freecad_conformal.layers.model import LayerSettings

    cone = Part.makeCone(12, 2, 14)
    width = check_options(cone, PlanOptions())[2]
    layers = LayerSettings(mode="adaptive", thickness=0.75 * width)
    assert layers.bounds[1] > width * 1.1           # the case: 1.5 x above the bead
    result = plan_additive(cone, PlanOptions(layers=layers, root=(0.0, 0.0, 1.0),
                                             decompose=False))
    tallest = max(layer.thickness_max for stack in result.layers.values() for layer in stack)
    assert width * 0.9 < tallest <= width * (1 + 1e-9)
    with pytest.raises(PlanError, match=r"minimum layer height \(--layer-min / LayerMin\)"):
        check_options(cone, PlanOptions(layers=LayerSettings(
            mode="adaptive", thickness=width, min_thickness=1.05 * width)))
