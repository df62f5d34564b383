"""(u, v) of surface points by Newton from a grid, against where the points came from."""
from __future__ import annotations

import math
import random

import numpy as np
import pytest

from freecad_conformal.geometry.uv_projection import SurfaceProjector


def _helicoid(App, Part, turns: float = 3.0):
    """A helicoid's strip, r 2..4 mm, rising 2 mm a turn: the same point height recurs
    every turn, as on a thread, so only the right start finds the right turn."""
    rows = []
    for r in (2.0, 2.7, 3.3, 4.0):
        rows.append([App.Vector(r * math.cos(t), r * math.sin(t), 2.0 * t / (2 * math.pi))
                     for t in np.linspace(0.0, 2 * math.pi * turns, int(24 * turns))])
    surface = Part.BSplineSurface()
    surface.interpolate(rows)
    return surface


class _WithoutOcc:
    """A surface whose OCC projection must not be needed."""

    def __init__(self, surface) -> None:
        self._surface = surface

    def __getattr__(self, name):
        return getattr(self._surface, name)

    def parameter(self, point):
        raise AssertionError(f"Newton did not reach {point}: OCC was asked")


def test_points_of_a_many_turn_surface_project_to_their_own_parameters(App, Part):
    """Twelve turns, as on the screw thread: with a 24-sample grid the nearest sample was
    often on another turn and Newton never reached the point."""
    surface = _helicoid(App, Part, turns=12.0)
    projector = SurfaceProjector(_WithoutOcc(surface))
    u0, u1, v0, v1 = surface.bounds()
    rng = random.Random(3)
    for _ in range(60):
        u, v = rng.uniform(u0, u1), rng.uniform(v0, v1)
        found = projector.parameter(surface.value(u, v))
        assert found == pytest.approx((u, v), abs=1e-6 * max(u1 - u0, v1 - v0))


def test_a_point_off_the_surface_is_left_to_occ(App, Part):
    surface = _helicoid(App, Part, turns=1.0)
    point = App.Vector(3.0, 0.0, 0.5)      # between the strip's sheets: on no sheet
    assert SurfaceProjector(surface).parameter(point) == pytest.approx(surface.parameter(point))
