"""Sections of a solid of polygon faces from its vertices (geometry/polyhedral.py)."""
from __future__ import annotations

import numpy as np

from freecad_conformal.geometry.frames import LayerFrame
from freecad_conformal.geometry.polyhedral import PolyhedronSlicer
from freecad_conformal.geometry.sections import PlanarSlicer
from freecad_conformal.layers.model import as_multipolygon


def _framed_block(App, Part):
    """A slanted frame: a block with a square hole through it and a notch cut in its side,
    so sections have holes and non-convex outlines."""
    block = Part.makeBox(40, 30, 20)
    hole = Part.makeBox(10, 10, 40, App.Vector(15, 10, -10))
    notch = Part.makeBox(10, 12, 40, App.Vector(-5, 9, -10))
    part = block.cut(hole).cut(notch)
    part.rotate(App.Vector(0, 0, 0), App.Vector(1, 2, 0), 23.0)
    return part


def test_sections_from_vertices_are_the_exact_sections(App, Part):
    """Islands, holes and notches, along slanted directions: the regions the exact cut
    makes, to rounding."""
    part = _framed_block(App, Part)
    checked = 0
    for direction in ((0, 0, 1), (1, 1, 1), (0.3, -1, 0.2)):
        slicer = PlanarSlicer(part, direction)
        quick = PolyhedronSlicer.of(part, slicer.frame)
        low, high = slicer.extent(0)
        for height in np.linspace(low + 0.37, high - 0.41, 12):
            region = quick.section(float(height))
            exact = slicer.section(float(height))
            want = as_multipolygon(exact.polygons())
            assert region.symmetric_difference(want).area < 1e-9 * max(want.area, 1.0)
            assert len(region.geoms) == len(want.geoms)
            checked += sum(len(p.interiors) for p in region.geoms)
    assert checked > 0          # some sections had the hole


def test_only_polygon_faced_solids_and_planes_clear_of_vertices(App, Part):
    frame = LayerFrame.for_direction((0.0, 0.0, 1.0))
    assert PolyhedronSlicer.of(Part.makeCylinder(5, 10), frame) is None
    box = Part.makeBox(10, 10, 10)
    quick = PolyhedronSlicer.of(box, frame)
    assert quick.section(10.0) is None and not quick.clear_of_vertices(1e-7)
    assert quick.section(3.0).area == 100.0
    assert quick.section(12.0).is_empty
