"""Runs of walls along the slicing direction: their sections are cut once and moved, and the
moved ones are what a cut would give."""
from __future__ import annotations

import numpy as np
import pytest

from freecad_conformal.geometry.prism_runs import copy_sources, free_runs, is_along, is_wall
from freecad_conformal.geometry.sections import PlanarSlicer

Z = np.array([0.0, 0.0, 1.0])


def test_free_runs_are_the_gaps_between_blocked_spans():
    assert free_runs([(0.0, 0.0), (10.0, 12.0), (2.0, 3.0), (2.5, 4.0)]) == [(0.0, 2.0), (4.0, 10.0)]
    assert free_runs([(0.0, 5.0), (1.0, 2.0)]) == []


def test_each_height_copies_the_first_of_its_run_and_heights_outside_runs_are_cut():
    runs = [(1.0, 3.0), (5.0, 9.0)]
    heights = [0.5, 1.5, 2.5, 3.0, 6.0, 4.0, 5.5, 8.9, 9.5]
    assert copy_sources(runs, heights) == [0, 1, 1, 3, 4, 5, 4, 4, 8]
    assert copy_sources([], heights) == list(range(len(heights)))


def test_walls_are_planes_cylinders_and_extrusions_along_the_direction(Part, App):
    box = Part.makeBox(10, 10, 10)
    walls = [is_wall(face.Surface, Z) for face in box.Faces]
    assert walls.count(True) == 4 and walls.count(False) == 2
    assert is_wall(Part.makeCylinder(2, 5).Faces[0].Surface, Z)
    lying = Part.makeCylinder(2, 5, App.Vector(0, 0, 0), App.Vector(1, 0, 0))
    assert not is_wall(lying.Faces[0].Surface, Z)
    assert not is_wall(Part.makeCone(2, 1, 5).Faces[0].Surface, Z)
    tilted = box.copy()
    tilted.rotate(App.Vector(0, 0, 0), App.Vector(1, 0, 0), 1e-4)
    assert [is_wall(face.Surface, Z) for face in tilted.Faces].count(True) == 2
    ellipse = Part.Ellipse(App.Vector(0, 0, 0), 4, 2).toShape()
    assert is_wall(ellipse.extrude(App.Vector(0, 0, 5)).Faces[0].Surface, Z)
    assert [is_along(edge, Z) for edge in box.Edges].count(True) == 4


def _countersunk_plate(Part, App):
    """A 10 mm plate with a round hole, countersunk over its top 2 mm: walls from 0 to 8."""
    plate = Part.makeBox(30, 20, 10).cut(Part.makeCylinder(3, 10, App.Vector(15, 10, 0)))
    return plate.cut(Part.makeCone(3, 5, 2, App.Vector(15, 10, 8)))


def test_a_runs_sections_are_moved_copies_of_its_first_equal_to_cuts(Part, App):
    plate = _countersunk_plate(Part, App)
    heights = [0.1 + 0.2 * k for k in range(50)]
    slicer = PlanarSlicer(plate, Z)
    moved = slicer.sections(heights, with_loops=True)
    cut_heights = sum(slicer.counts.values())
    inside = [h for h in heights if 0.0 < h < 8.0]
    assert cut_heights == len(heights) - len(inside) + 1
    alone = PlanarSlicer(plate, Z)
    for height, section in zip(heights, moved):
        fresh = alone.section(height)
        assert section.height == height
        assert all(abs(v.Point.z - height) < 1e-12 for f in section.faces for v in f.Vertexes)
        assert section.area == pytest.approx(fresh.area, rel=1e-12)
        np.testing.assert_allclose(section.centroid, fresh.centroid, atol=1e-9)
        difference = section.polygons().symmetric_difference(fresh.polygons()).area
        assert difference < 1e-3 * fresh.area
    # the countersink's sections shrink the hole: not copies
    assert moved[-1].area < moved[0].area - 1.0


def test_a_slicer_turned_to_another_direction_finds_its_own_runs(Part, App):
    plate = _countersunk_plate(Part, App)
    slicer = PlanarSlicer(plate, Z)
    slicer.sections([1.0, 2.0])
    across = slicer.turned((1.0, 0.0, 0.0))
    heights = [0.5 + k for k in range(30)]
    sections = across.sections(heights)
    fresh = PlanarSlicer(plate, (1.0, 0.0, 0.0))
    for height, section in zip(heights, sections):
        assert section.area == pytest.approx(fresh.section(height).area, rel=1e-12)
