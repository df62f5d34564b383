"""Conformal features on real faces: rods, shells, patterns, channels, and the command."""
from __future__ import annotations

import math

import numpy as np
import pytest

from freecad_conformal.cli import main
from freecad_conformal.errors import PlanError
from freecad_conformal.geometry.faces import face_kind, normals_at, points_at
from freecad_conformal.paths.features import channels, feeds, patterns, rods, shells
from freecad_conformal.paths.features.outlines import region_from_rings, svg_path_rings, text_rings
from freecad_conformal.post.machine import load_machine
from freecad_conformal.post.program import post_toolpath
from freecad_conformal.process.library import ToolLibrary
from freecad_conformal.toolpath import KINDS


@pytest.fixture(scope="module")
def library():
    return ToolLibrary.load()


def _face(shape, kind):
    return next(f for f in shape.Faces if face_kind(f) == kind)


@pytest.mark.parts
def test_rods_on_the_revolved_sphere(parts_dir, Part, library):
    sphere = Part.read(str(parts_dir / "revolved_sphere.step")).Faces[0]
    centre = np.array(tuple(sphere.Surface.Center))
    tool = library.get("uv_small")
    layout = rods.sphere_layout(centre, (0, 0, 1), 5.0, 2.0, 0.8, 1.5, tool.max_tilt)
    rods.check_layout(layout, tool)
    builder = rods.rods_toolpath(layout, tool, feeds.rod_settings(tool, [1.0, 0.8]))
    tp = builder.build()
    cure = np.flatnonzero(tp.kind == KINDS.index("cure"))
    assert len(cure) == 2 * len(layout.bases)             # two diameters per rod
    starts = tp.segment_starts
    for k, seg in enumerate(cure[::2]):
        base = tp.points[starts[seg]]
        tip = tp.points[starts[cure[2 * k + 1] + 1] - 1]
        normal = (base - centre) / 5.0
        assert np.linalg.norm(base - centre) == pytest.approx(5.0, abs=1e-9)
        np.testing.assert_allclose(tip - base, 1.5 * normal, atol=1e-9)   # along the normal
        np.testing.assert_allclose(tp.axes[starts[seg]], normal, atol=1e-9)
    # slower feed for the thicker base piece
    assert tp.feed[cure[0]] < tp.feed[cure[1]]
    post_toolpath(tp, load_machine("head_a_table_c"))     # reachable on the METHODS machine


def test_colliding_rods_are_refused(Part, library):
    tool = library.get("uv_small")
    layout = rods.sphere_layout((0, 0, 0), (0, 0, 1), 10.0, 0.9, 1.2, 6.0, tool.max_tilt, rings=2)
    with pytest.raises(PlanError, match="hits rod"):
        rods.check_layout(layout, tool, "rods on Face1")


def test_sphere_shell_rings(App, Part, library):
    cap = Part.makeSphere(20, App.Vector(0, 0, 0), App.Vector(0, 0, 1), 40, 90).Faces[0]
    tool = library.get("uv_large")
    rings = shells.base_shell(cap, tool, 2.0, layers=2, layer=1.0)
    per_layer = len(rings) // 2
    first = rings[:per_layer]
    # rings 2 mm apart on the surface (arc along the meridian), offset by half a layer
    polar = [math.acos(r.points[0][2] / np.linalg.norm(r.points[0])) for r in first]
    assert np.diff(sorted(polar)) * 20 == pytest.approx(np.full(per_layer - 1, 2.0))
    np.testing.assert_allclose(np.linalg.norm(first[0].points, axis=1), 20.5, atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(rings[-1].points, axis=1), 21.5, atol=1e-9)
    for ring in rings:
        np.testing.assert_allclose(ring.points[0], ring.points[-1], atol=1e-9)   # full turn
        np.testing.assert_allclose(ring.axes, ring.points / np.linalg.norm(ring.points, axis=1)[:, None],
                                   atol=1e-9)
        assert ring.tilt <= tool.max_tilt
    whole = Part.makeSphere(20, App.Vector(0, 0, 0), App.Vector(0, 0, 1), 0, 90).Faces[0]
    with pytest.raises(PlanError, match="beyond what uv_large reaches"):
        shells.base_shell(whole, tool, 2.0)


def test_inverse_conical_cup(Part, library):
    cup = Part.makeCone(10, 20, 15).cut(Part.makeCone(7.7, 17.7, 15))
    inner = next(f for f in cup.Faces if face_kind(f) == "cone" and f.Surface.Radius < 9)
    tool = library.get("uv_large")
    on_face = shells.conical_cup(inner, tool, 8.0, layer=1.0, feed=24.0)
    rings = shells.conical_cup(inner, tool, 8.0, layer=1.0, feed=24.0, width=2.3)
    alpha = inner.Surface.SemiAngle
    z = [r.points[0][2] for r in on_face]
    assert z[0] == pytest.approx(0.25) and np.diff(z[1:]) == pytest.approx(np.ones(len(z) - 2))
    # the rings run on the wall's centre: 1.15 mm inside the material, along the face normal
    for ring, bare in zip(rings, on_face):
        offset = np.linalg.norm(ring.points - bare.points, axis=1)
        np.testing.assert_allclose(offset, 1.15, atol=1e-9)
    # inside the cup's wall (the face's normal points out of the material, into the cup);
    # the first ring's centre is below the cup's bottom (it bonds to the base)
    import FreeCAD as App
    for ring in rings[1:]:
        assert all(cup.isInside(App.Vector(*p), 1e-6, False) for p in ring.points[::7])
    assert rings[0].feed == 12.0 and all(r.feed == 24.0 for r in rings[1:])
    for ring in rings:
        tilt = np.arccos(ring.axes @ np.array([0, 0, 1.0]))
        np.testing.assert_allclose(tilt, alpha, atol=1e-9)      # inclined at the cone angle
        assert np.ptp(ring.points[:, 2]) < 1e-9                  # one height per layer


def _naive_distortion(face, lines, centre):
    """Pattern mapped by scaling u and v with the face's mean arc lengths (no metric)."""
    u0, u1, v0, v1 = face.ParameterRange
    row = points_at(face, np.column_stack((np.linspace(u0, u1, 200), np.full(200, centre[1]))))
    col = points_at(face, np.column_stack((np.full(200, centre[0]), np.linspace(v0, v1, 200))))
    su = np.linalg.norm(np.diff(row, axis=0), axis=1).sum() / (u1 - u0)
    sv = np.linalg.norm(np.diff(col, axis=0), axis=1).sum() / (v1 - v0)
    worst = 0.0
    for line in lines:
        fine = patterns.densify(line)
        uv = np.column_stack((centre[0] + fine[:, 0] / su, centre[1] + fine[:, 1] / sv))
        mapped = np.linalg.norm(np.diff(points_at(face, uv), axis=0), axis=1)
        planar = np.linalg.norm(np.diff(fine, axis=0), axis=1)
        worst = max(worst, float(np.max(np.abs(mapped / planar - 1))))
    return worst


LINES = [np.array([[-4.0, 0.0], [4.0, 0.0]]), np.array([[0.0, -4.0], [0.0, 4.0]]),
         np.array([[-3.0, -3.0], [3.0, 3.0]])]


def test_patterns_are_not_stretched(App, Part):
    cylinder = _face(Part.makeCylinder(10, 30), "cylinder")
    cone = _face(Part.makeCone(10, 20, 30), "cone")
    for face in (cylinder, cone):
        u0, u1, v0, v1 = face.ParameterRange
        mapping = patterns.FaceMapping(face, (1.0, 0.5 * (v0 + v1)))
        assert patterns.distortion(face, mapping, LINES) < 1e-4          # developable: exact
    sphere = Part.makeSphere(20).Faces[0]
    mapping = patterns.FaceMapping(sphere, (1.0, 0.3))
    radial = [np.array([[0.0, 0.0], [4.0 * math.cos(t), 4.0 * math.sin(t)]]) for t in (0.3, 1.9, 4.0)]
    assert patterns.distortion(sphere, mapping, radial) < 1e-4           # geodesic distances exact
    # a doubly curved B-spline face: the metric-aware map against naive (u, v) scaling
    pts = [[App.Vector(i * 10, j * 10, 3 * math.sin(i * 0.8) * math.cos(j * 0.6)) for j in range(6)]
           for i in range(6)]
    surface = Part.BSplineSurface()
    surface.interpolate(pts)
    wavy = surface.toShape()
    mapping = patterns.FaceMapping(wavy, (0.5, 0.5))
    ours = patterns.distortion(wavy, mapping, LINES)
    naive = _naive_distortion(wavy, LINES, (0.5, 0.5))
    assert ours < 0.01 and naive > 5 * ours, (ours, naive)


def test_text_pattern_stacked_along_the_normal(Part):
    face = _face(Part.makeCylinder(10, 30), "cylinder")
    region = region_from_rings(text_rings("Hi", 5.0))
    paths, mapping = patterns.pattern_paths(face, region, 0.3, 1.0, 0.5, centre=(0.0, 15.0))
    layers = {p.layer for p in paths}
    assert layers == {0, 1}
    for path in paths:
        radius = np.linalg.norm(path.points[:, :2], axis=1)
        np.testing.assert_allclose(radius, 10.0 + (path.layer + 0.5) * 0.5, atol=1e-9)
    with pytest.raises(PlanError, match="larger than its face"):
        patterns.pattern_paths(face, region_from_rings(text_rings("HELLO", 25.0)), 0.3, 1.0, 0.5,
                               centre=(0.0, 15.0))


def test_svg_pattern_runs_off_a_partial_face(App, Part):
    cap = Part.makeSphere(10, App.Vector(0, 0, 0), App.Vector(0, 0, 1), 60, 90).Faces[0]
    big = region_from_rings(svg_path_rings("M0 0 H20 V20 H0 Z"))
    with pytest.raises(PlanError, match="runs off the face"):
        patterns.pattern_paths(cap, big, 0.3, 1.0, 0.5, centre=(0.0, 1.4))


def test_channels_change_tools(App, Part, library):
    face = _face(Part.makeCylinder(15, 40, App.Vector(-20, 0, 0), App.Vector(1, 0, 0)), "cylinder")
    tools = [t for t in library if t.kind == "uv_light_guide"]
    uv = np.array([[u, 20.0] for u in np.linspace(0, 2 * math.pi, 721)])
    top = uv[int(np.argmax(normals_at(face, uv)[:, 2]))]
    footprint, gaps = channels.straight_channels(3, 15.0, 1.0, 1.0)
    def setting_for(tool, width, what):
        return feeds.line_setting(tool, width, what=what)

    plan = channels.channels_toolpath(face, tools, footprint, gaps, 1.0, 0.5, setting_for,
                                      centre=tuple(top))
    assert (plan.base_tool.id, plan.wall_tool.id) == ("uv_large", "uv_small")
    tp = plan.builder.build()
    changes = [e.tool for e in tp.events if e.action == "tool_change"]
    assert len(changes) == 2 and changes[0] != changes[1]
    narrow, _ = channels.straight_channels(2, 15.0, 0.6, 1.0)
    with pytest.raises(PlanError, match="narrowest channel gap is 0.6"):
        channels.channels_toolpath(face, tools, narrow, _, 1.0, 0.5, setting_for, centre=tuple(top))


def test_feature_command_and_bad_input(App, Part, tmp_path, capsys):
    dome = tmp_path / "dome.brep"
    Part.makeSphere(20, App.Vector(0, 0, 0), App.Vector(0, 0, 1), 0, 90).exportBrep(str(dome))
    tube = tmp_path / "tube.brep"
    Part.makeCylinder(15, 40, App.Vector(-20, 0, 0), App.Vector(1, 0, 0)).exportBrep(str(tube))
    plate = tmp_path / "plate.brep"
    Part.makeBox(30, 30, 5).exportBrep(str(plate))
    out, gcode = tmp_path / "f.npz", tmp_path / "f.ngc"
    ok = main(["feature", str(dome), "--face", "Face1", "--kind", "rods", "--spacing", "3",
               "--rod-length", "2", "-o", str(out), "--gcode", str(gcode)])
    assert ok == 0 and out.exists() and gcode.exists()
    assert main(["feature", str(tube), "--face", "Face1", "--kind", "pattern", "--text", "Hi",
                 "-o", str(out)]) == 0
    bad = [
        (["--face", "Face9", "--kind", "rods"], dome, "Face9 is not in the part"),
        (["--face", "Face1", "--kind", "pattern", "--text", "HELLO WORLD", "--text-size", "15"],
         tube, "pattern on Face1: the pattern .* is larger than its face"),
        (["--face", "Face1", "--kind", "shell", "--tilt", "70", "--tool", "uv_large"], dome,
         "shell on Face1: a tilt of 70"),
        # the angled tool reaches 70° from the normal, but its body then dips into the dome
        (["--face", "Face1", "--kind", "shell", "--tilt", "70"], dome,
         r"shell on Face1: \d+ move\(s\) of the tool envelope hit the part"),
        (["--face", "Face1", "--kind", "rods", "--spacing", "0.8", "--rod-length", "6"], dome,
         "rods on Face1: the uv_small envelope"),
        (["--face", "Face6", "--kind", "rods"], plate, "rods on Face6: rods need a sphere or cylinder face"),
    ]
    for extra, part, message in bad:
        target, program = tmp_path / "bad.npz", tmp_path / "bad.ngc"
        capsys.readouterr()
        assert main(["feature", str(part), *extra, "-o", str(target), "--gcode", str(program)]) == 1
        import re
        assert re.search(message, capsys.readouterr().err), message
        assert not target.exists() and not program.exists()
