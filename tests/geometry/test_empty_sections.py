"""A plane that crosses a solid never comes back as an empty section (issue 20): when the
face-by-face cut and the Boolean both fail there, it is cut again and the report says so."""
from __future__ import annotations

import pytest

from freecad_conformal.errors import GeometryError
from freecad_conformal.geometry.sections import PlanarSlicer, planar_sections


def _failing_at(monkeypatch, height: float, also_nudged: bool = False, also_fuzzy: bool = False):
    """Make both first cuts (and optionally the retries) return nothing at `height`."""
    cut_faces, cut_boolean, fuzzy = (PlanarSlicer.cut_faces, PlanarSlicer.cut_boolean,
                                     PlanarSlicer._fuzzy_common)

    def faces(self, index, heights):
        return [[] if abs(h - height) < 1e-9 else r
                for h, r in zip(heights, cut_faces(self, index, heights))]

    def boolean(self, index, heights):
        near = 1e-3 if also_nudged else 1e-9
        return [[] if abs(h - height) < near else r
                for h, r in zip(heights, cut_boolean(self, index, heights))]

    def fuzzy_common(self, index, h):
        return [] if also_fuzzy else fuzzy(self, index, h)

    monkeypatch.setattr(PlanarSlicer, "cut_faces", faces)
    monkeypatch.setattr(PlanarSlicer, "cut_boolean", boolean)
    monkeypatch.setattr(PlanarSlicer, "_fuzzy_common", fuzzy_common)


def test_an_empty_cut_inside_the_part_is_cut_again_nudged(Part, monkeypatch):
    _failing_at(monkeypatch, 5.0)
    # The box's walls run its whole height: its first height given is cut, the others are
    # that section moved (geometry/prism_runs.py), so the failing one comes first.
    stack = planar_sections(Part.makeBox(10, 20, 30), heights=[5.0, 2.0, 8.0])
    assert [layer.area for layer in stack.layers] == pytest.approx([200.0] * 3, rel=1e-9)
    assert [layer.height for layer in stack.layers] == [5.0, 2.0, 8.0]
    assert stack.repairs == {5.0: "nudged +1e-04 mm"}
    assert stack.to_dict(False)["repaired_layers"] == [{"height": 5.0, "how": "nudged +1e-04 mm"}]


def test_then_by_a_fuzzy_boolean(Part, monkeypatch):
    _failing_at(monkeypatch, 5.0, also_nudged=True)
    stack = planar_sections(Part.makeCylinder(5, 30), heights=[5.0])
    assert stack.layers[0].area == pytest.approx(25 * 3.141592653589793, rel=1e-6)
    assert stack.repairs[5.0].startswith("fuzzy Boolean")


def test_and_when_everything_fails_the_height_is_named(Part, monkeypatch):
    _failing_at(monkeypatch, 5.0, also_nudged=True, also_fuzzy=True)
    with pytest.raises(GeometryError, match=r"section at height 5 mm came back empty .* solid 1"):
        planar_sections(Part.makeBox(10, 20, 30), heights=[5.0])


def test_and_a_loose_tolerance_that_may_be_why_is_named(Part, monkeypatch):
    _failing_at(monkeypatch, 5.0, also_nudged=True, also_fuzzy=True)
    box = Part.makeBox(10, 20, 30)
    box.fixTolerance(0.05, Part.Vertex)     # usual: not named
    with pytest.raises(GeometryError, match=r"cuts all failed$"):
        planar_sections(box, heights=[5.0])
    box.fixTolerance(2.0, Part.Vertex)
    with pytest.raises(GeometryError, match=r"a vertex carries a tolerance of 2 mm .*repair"):
        planar_sections(box, heights=[5.0])


def test_a_plane_beyond_or_touching_the_part_stays_empty_without_a_repair(Part):
    stack = planar_sections(Part.makeBox(10, 20, 30), heights=[-1.0, 31.0])
    assert [layer.area for layer in stack.layers] == [0.0, 0.0]
    assert stack.repairs == {}
