"""Tool choice end to end, travels that clear what is built, exact pattern centres, textures."""
from __future__ import annotations

import math

import numpy as np
import pytest

from freecad_conformal.errors import PlanError
from freecad_conformal.geometry.faces import face_kind, normals_at, smallest_radius
from freecad_conformal.jobs.feature import plan_feature, plan_features
from freecad_conformal.paths.features import clearance, feeds, rods, texture
from freecad_conformal.paths.features.centre import facing_point
from freecad_conformal.paths.features.choice import choose_for_face
from freecad_conformal.process.library import ToolLibrary
from freecad_conformal.process.tools import Envelope
from freecad_conformal.toolpath import KINDS, ToolpathBuilder


@pytest.fixture(scope="module")
def library(tmp_path_factory):
    return ToolLibrary.load(user_dir=tmp_path_factory.mktemp("user"))


def _three_surface_part(App, Part):
    """A block whose top carries a spherical cap (R 40) joined by a 0.6 mm fillet."""
    base = Part.makeBox(60, 60, 10, App.Vector(-30, -30, -10))
    cap = Part.makeSphere(40, App.Vector(0, 0, -32)).common(Part.makeCylinder(30, 20))
    fused = base.fuse(cap).removeSplitter()

    def rim(edge):
        try:
            return abs(edge.Curve.Radius - 24.0) < 1e-6
        except (AttributeError, TypeError):
            return False
    return fused.makeFillet(0.6, [e for e in fused.Edges if rim(e)])


def _faces(shape):
    sphere = next(f for f in shape.Faces if face_kind(f) == "sphere")
    fillet = next(f for f in shape.Faces if abs(smallest_radius(f) - 0.6) < 1e-6)
    wall = next(f for f in shape.Faces if face_kind(f) == "plane"
                and np.allclose(tuple(f.normalAt(0, 0)), (1, 0, 0), atol=1e-9))
    return sphere, fillet, wall


def test_three_surfaces_three_tools(App, Part, library, tmp_path):
    shape = _three_surface_part(App, Part)
    sphere, fillet, wall = _faces(shape)
    top = next(f for f in shape.Faces if face_kind(f) == "plane"
               and np.allclose(tuple(f.normalAt(0, 0)), (0, 0, 1), atol=1e-9))
    tools = [t for t in library if t.kind == "uv_light_guide"]
    big = choose_for_face(sphere, tools, 1.0, None)
    small = choose_for_face(fillet, tools, 0.3, None)
    side = choose_for_face(wall, tools, 1.0, None)
    # large sphere: the largest straight tool fits both rules at its 36.9° rim
    assert big.tool.id == "uv_large"
    assert 35.0 < math.degrees(big.theta) < 36.87      # up to the rim at asin(24/40)
    # 0.6 mm fillet: 2·sqrt(0.3·(1.2 − 0.3)) = 1.04 mm < 1.57: only the 0.3 mm tool reaches
    assert small.tool.id == "uv_small"
    assert "uv_large (dt 1.57 mm > 2·sqrt(cd(2rs − cd)) = 1.039" in small.reason
    # vertical wall: 90° is beyond a straight head's W 60°; the 45° head reaches it
    assert side.tool.id == "uv_large_angled45"
    assert "rotation 90.0° outside the 0.0°..60.0°" in side.reason
    # one program on the part: a shell on the sphere, a mark on the wall, text on the flat
    # top beside the cap, each tool chosen by the same rules, a change (and a retract home)
    # each time the tool changes, and every move checked against the part and what is built
    (tmp_path / "bar.svg").write_text("M0 0 H6 V3 H0 Z")
    mark = {"width": 1.5, "svg": str(tmp_path / "bar.svg"), "at_point": (30.0, 0.0, -5.0)}
    features = [(sphere, "shell", {"width": 2.0}, "shell on the sphere"),
                (wall, "pattern", mark, "mark on the wall"),
                (top, "pattern", {"text": "Hi", "text_size": 3.0, "height": 0.5, "layer": 0.5,
                                  "at_point": (0.0, -27.5, 0.0)}, "text on the top")]
    tp = plan_features(shape, features, "three")
    changes = [e.tool for e in tp.events if e.action == "tool_change"]
    names = dict(item.split(" ") for item in tp.metadata["tools"].split(", "))
    assert [names[f"T{n}"] for n in changes] == ["uv_large", "uv_large_angled45", "uv_small"]
    assert "rotation 90.0° outside" in tp.metadata["tool_choice"]
    # before each change after the first the tool retracts 20 mm along its axis
    homes = [e.segment for e in tp.events if e.action == "tool_change"][1:]
    for segment in homes:
        assert tp.kind[segment] == KINDS.index("travel")


def _plain_head(diameter: float, library):
    tool = library.get("uv_small").copy()
    tool.envelope = Envelope(diameter, 0.0, diameter, 60.0)
    return tool


def test_old_straight_travels_hit_the_rods_new_ones_clear(library):
    """Issue 23: with a plain 3 mm head, straight travels 2 mm above the surface cut into
    the rods just built; the travels over the tips clear every rod."""
    tool = _plain_head(3.0, library)
    layout = rods.sphere_layout((0, 0, 0), (0, 0, 1), 20.0, 3.0, 1.2, 4.0, tool.max_tilt)
    rods.check_layout(layout, tool)                         # the cures themselves are clear
    setting = feeds.rod_settings(library.get("uv_small"), [1.2])
    old = ToolpathBuilder()
    for base, axis in zip(layout.bases, layout.axes):      # the former strategy
        old.add_segment([base + 2.0 * axis, base], axes=axis, kind="travel", feed=600.0, tool=1)
        old.add_segment([base, base + 4.0 * axis], axes=axis, kind="cure", feed=45.0, tool=1)
        old.add_segment([base + 6.0 * axis], axes=axis, kind="travel", feed=600.0, tool=1)
    old_tp = old.build()
    widths = np.where(old_tp.kind == KINDS.index("cure"), 1.2, 0.0)
    hits = clearance.check_toolpath(old_tp, {1: tool.envelope}, widths)
    # 115 of the 120 travels (measured), by up to 0.30 mm
    assert len(hits) > 100 and all(h.kind == "travel" for h in hits)
    assert max(h.overlap for h in hits) > 0.25
    new_tp = rods.rods_toolpath(layout, tool, setting, 1).build()
    widths = np.where(new_tp.kind == KINDS.index("cure"), 1.2, 0.0)
    assert clearance.check_toolpath(new_tp, {1: tool.envelope}, widths) == []


def test_collision_rules(App, Part, library):
    dome = Part.makeSphere(20, App.Vector(0, 0, 0), App.Vector(0, 0, 1), 0, 90)
    face = dome.Faces[0]
    # d = 3 mm on R 20: 8.6° between rods, more than the envelope needs (6°), less than
    # rule (i) asks for a 3 mm head (12.2°)
    values = {"spacing": 3.0, "rod_length": 3.0, "rings": 3}
    tp = plan_feature(face, "rods", values, "rods", part=dome)
    assert tp.metadata["collision_rule"] == "envelope"
    with pytest.raises(PlanError, match=r"rule \(i\) needs 12\.\d+° between rods"):
        plan_feature(face, "rods", {**values, "collision_rule": "published"}, "rods", part=dome)
    tp = plan_feature(face, "rods", {**values, "spacing": 5.0, "collision_rule": "published"},
                      "rods", part=dome)
    assert tp.metadata["collision_rule"] == "published"


def test_pattern_centre_is_exact(App, Part):
    up = np.array([0.3, 0.2, 1.0]) / np.linalg.norm([0.3, 0.2, 1.0])
    sphere = Part.makeSphere(20).Faces[0]
    uv = facing_point(sphere, up)
    assert normals_at(sphere, np.array([uv]))[0] @ up == pytest.approx(1.0, abs=1e-12)
    tube = Part.makeCylinder(15, 40, App.Vector(-20, 0, 0), App.Vector(1, 0, 0)).Faces[0]
    uv = facing_point(tube, (0, 0, 1))
    assert normals_at(tube, np.array([uv]))[0] == pytest.approx([0, 0, 1], abs=1e-12)
    # a B-spline face: refined search, better than the former 48 × 48 grid (3.75°)
    pts = [[App.Vector(x, y, 2 * math.sin(x / 4) * math.cos(y / 5)) for y in range(0, 21, 2)]
           for x in range(0, 21, 2)]
    surface = Part.BSplineSurface()
    surface.interpolate(pts)
    wavy = surface.toShape()
    uv = facing_point(wavy, up)
    found = math.degrees(math.acos(min(normals_at(wavy, np.array([uv]))[0] @ up, 1.0)))
    # no normal there is parallel to `up`: the best of a 200 × 200 grid is 1.6022°
    from freecad_conformal.geometry.faces import domain_grid
    grid = domain_grid(wavy, 200)
    fine = math.degrees(math.acos(float(np.max(normals_at(wavy, grid) @ up))))
    assert found <= fine + 1e-6


def test_texture_stamps(App, Part, library, tmp_path):
    tube = Part.makeCylinder(15, 40, App.Vector(-20, 0, 0), App.Vector(1, 0, 0))
    face = next(f for f in tube.Faces if face_kind(f) == "cylinder")
    tp = plan_feature(face, "texture", {"tool": "uv_mask_star", "pitch": 4.0, "extent": 8.0,
                                        "thickness": 0.5}, "texture", part=tube)
    cure = np.flatnonzero(tp.kind == KINDS.index("cure"))
    assert len(cure) == 9                                    # 3 × 3 grid
    starts = tp.segment_starts
    bases = tp.points[starts[cure]]                          # each stamp starts on the face
    tops = tp.points[starts[cure] + 1]
    np.testing.assert_allclose(np.linalg.norm(tops - bases, axis=1), 0.5, atol=1e-9)
    radial = np.hypot(bases[:, 1], bases[:, 2])
    np.testing.assert_allclose(radial, 15.0, atol=1e-9)
    # neighbours 4 mm apart on the surface (arc round the axis or along it)
    arcs = 15.0 * np.arctan2(bases[:, 1], bases[:, 2])
    gaps = np.diff(np.sort(np.unique(np.round(arcs, 6))))
    np.testing.assert_allclose(gaps, 4.0, atol=1e-6)
    star = library.get("uv_mask_star").spec.mask
    # a regular five-point star of outer radius R and inner 0.382·R: 10·(½·R·0.382R·sin 36°)
    assert texture.mask_area(star) == pytest.approx(5 * 1.5 * 0.382 * 1.5 * math.sin(math.pi / 5))
    dwell = plan_feature(face, "texture", {"tool": "uv_mask_disk", "stamp": "dwell",
                                           "thickness": 0.3, "layout": "curve", "extent": 8.0,
                                           "pitch": 4.0}, "dots", part=tube)
    waits = [e.seconds for e in dwell.events if e.action == "dwell"]
    expected = 10.0 * math.exp(0.3 / 0.15) * 1e-5 * math.pi * 9 / 4 / 0.495
    assert waits == pytest.approx([expected] * 3)
    with pytest.raises(PlanError, match="uv_small has no mask"):
        plan_feature(face, "texture", {"tool": "uv_small"}, "texture", part=tube)
