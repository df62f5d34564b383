"""Mandrel builds (METHODS section 5) on a real B-rep spring: layers, band angle, G-code."""
from __future__ import annotations

import math
import re

import numpy as np
import pytest

from freecad_conformal.cli import main
from freecad_conformal.errors import PlanError
from freecad_conformal.jobs.mandrel import (
    MandrelAxis, band_inclination, mandrel_layers, plan_mandrel, spring_solid)
from freecad_conformal.post.machine import load_machine
from freecad_conformal.post.verify import verify_program

pytestmark = pytest.mark.slow   # the spring plans take ~10 s in all

RADIUS, PITCH, TURNS, SECTION = 10.0, 8.0, 3.0, 2.0
LAYER, WIDTH = 0.5, 0.5


@pytest.fixture(scope="module")
def spring():
    return spring_solid(RADIUS, PITCH, TURNS, SECTION, SECTION)


@pytest.fixture(scope="module")
def rotary(spring, tmp_path_factory):
    out = tmp_path_factory.mktemp("mandrel") / "spring.gcode"
    return plan_mandrel(spring, "rotary_mandrel", "fdm_0p4", LAYER, out, width=WIDTH)


@pytest.fixture(scope="module")
def linear(spring):
    return plan_mandrel(spring, "rotary_mandrel", "fdm_0p4", LAYER, None, width=WIDTH,
                        mapping="linear")


def _moves(text: str) -> list[dict[str, float]]:
    rows = []
    for line in text.splitlines():
        if line.startswith(("G0", "G1")):
            rows.append({m.group(1): float(m.group(2))
                         for m in re.finditer(r"([XYZAEF])(-?[\d.]+)", line)} | {"G": line[:2]})
    return rows


def test_spring_volume(spring):
    # swept square: area × path length of the section's centroid
    # Pappus: the section swept round its centroid radius (the pitch adds a shear only)
    centre = RADIUS + SECTION / 2
    assert spring.Volume == pytest.approx(SECTION ** 2 * TURNS * 2 * math.pi * centre, rel=1e-4)


def test_layers_follow_the_band_inclination(rotary):
    """Every layer maps to the mandrel: in the plane scaled at the mandrel radius r the
    raster lines run at α = atan(t / (2πr)) whatever the layer radius."""
    alpha = band_inclination(PITCH, RADIUS)
    assert len(rotary.layers) == int(SECTION / LAYER)
    for layer in rotary.layers:
        for line in layer.lines:
            steps = np.diff(line, axis=0)
            long = steps[np.argmax(np.abs(steps[:, 0]))]
            angle = math.atan2(long[1], long[0] * RADIUS)
            assert abs(math.sin(angle - alpha)) < 1e-3, (layer.index, math.degrees(angle))
        # the long lines wrap TURNS times round the mandrel (less the band's ends)
        span = max(float(np.ptp(line[:, 0])) for line in layer.lines)
        assert span > 2 * math.pi * (TURNS - 0.5)


def test_one_block_per_straight_line_of_the_unrolled_plane(rotary):
    lines = sum(len(line) - 1 for layer in rotary.layers for line in layer.lines)
    polylines = sum(len(layer.lines) for layer in rotary.layers)
    moves = _moves(rotary.gcode)
    assert len(moves) == rotary.blocks
    deposits = [m for m in moves if "E" in m]
    assert len(deposits) == lines
    # travels: at most lift, move, lower per polyline (fewer where legs are collinear)
    assert len(moves) - 1 - len(deposits) <= 3 * polylines
    swept = [abs(b["A"] - a["A"]) for a, b in zip(moves, moves[1:]) if "A" in a and "A" in b]
    assert max(swept) > 360 * (TURNS - 0.5)            # a multi-turn helix in one G1


@pytest.mark.slow
def test_rotary_program_replays_onto_the_design(rotary):
    deviation = verify_program(rotary.gcode, load_machine("rotary_mandrel"), rotary.toolpath)
    assert deviation.position < 0.011 and math.degrees(deviation.angle) < 0.051


def test_linear_mapping_compensates_extrusion_and_feed(linear):
    machine = load_machine("rotary_mandrel")
    r0 = linear.first_radius
    k = LAYER * WIDTH / (math.pi * machine.filament_diameter ** 2 / 4)
    moves = _moves(linear.gcode)
    position = {"X": 0.0, "Y": 0.0, "Z": 0.0}
    feed = None
    checked = {"first": 0, "outer": 0}
    for move in moves:
        step = {a: move.get(a, position[a]) - position[a] for a in "XYZ"}
        position.update({a: move.get(a, position[a]) for a in "XYZ"})
        feed = move.get("F", feed)
        if "E" not in move:
            continue
        ri = position["Z"]
        lx, ly = step["X"], step["Y"]
        # Z and Y are printed to 4 decimals: Ri and Ly carry ±5e-5 mm
        assert move["E"] == pytest.approx(k * math.hypot(ri / r0 * ly, lx), rel=2e-5, abs=2e-5)
        true = math.hypot(lx, ri / r0 * ly)
        assert feed == pytest.approx(2000.0 * math.hypot(lx, ly) / true, rel=1e-5)
        checked["first" if abs(ri - r0) < 1e-3 else "outer"] += 1
    assert checked["first"] > 0 and checked["outer"] > 0


def test_both_mappings_agree_on_material_and_blocks(rotary, linear):
    assert linear.blocks == rotary.blocks
    assert linear.material_volume == pytest.approx(rotary.material_volume, rel=1e-3)
    # beads fill the section: volume of the layers' lines close to the solid's
    assert rotary.material_volume == pytest.approx(SECTION ** 2 * TURNS * 2 * math.pi
                                                   * (RADIUS + SECTION / 2), rel=0.15)


def test_not_a_mandrel_machine_writes_nothing(spring, tmp_path):
    out = tmp_path / "x.gcode"
    with pytest.raises(PlanError, match="not a rotary mandrel"):
        plan_mandrel(spring, "trunnion_ac", "fdm_0p4", LAYER, out)
    assert not out.exists()


def test_part_on_the_axis_is_refused(App, Part):
    axis = MandrelAxis.make((0, 0, 0), (1, 0, 0))
    with pytest.raises(PlanError, match="crosses the mandrel axis"):
        mandrel_layers(Part.makeCylinder(5, 10, App.Vector(0, 0, 0), App.Vector(1, 0, 0)),
                       axis, 0.5, 0.5)


@pytest.mark.slow
def test_mandrel_command(spring, tmp_path, capsys):
    part = tmp_path / "spring.brep"
    spring.exportBrep(str(part))
    out = tmp_path / "spring.gcode"
    assert main(["mandrel", str(part), "--layer", "0.5", "--width", "0.5", "-o", str(out),
                 "--mapping", "linear"]) == 0
    assert "G-code blocks" in capsys.readouterr().out
    assert out.read_text().count("\nG1 ") > 10
    assert main(["mandrel", str(part), "--machine", "three_axis", "-o", str(tmp_path / "no.gcode")]) == 1
    assert not (tmp_path / "no.gcode").exists()


def test_plan_mandrel_option_runs_the_mandrel_planner(tmp_path, App, Part):
    """`plan --mandrel` reaches the same planner as `mandrel`: a tube on the mandrel axis."""
    from freecad_conformal.cli import main

    from freecad_conformal.post.machine import load_machine

    machine = load_machine("rotary_mandrel")
    [axis] = machine.rotary
    tube = Part.makeCylinder(12, 10, App.Vector(*axis.pivot), App.Vector(*axis.direction)).cut(
        Part.makeCylinder(10, 10, App.Vector(*axis.pivot), App.Vector(*axis.direction)))
    part = tmp_path / "tube.brep"
    tube.exportBrep(str(part))
    out = tmp_path / "tube.gcode"
    assert main(["plan", str(part), "--mandrel", "--layer", "1", "-o", str(out)]) == 0
    text = out.read_text()
    assert " A" in text and "G1" in text
