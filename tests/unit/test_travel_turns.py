"""Travels between sub-parts and between layers turn the tool axis where the machine can
follow it: through +Z, where a tilting table is singular, not close by it."""
from __future__ import annotations

import math

import numpy as np
import pytest

from freecad_conformal.errors import PostError
from freecad_conformal.paths import approach
from freecad_conformal.paths.approach import POLE_CONE, UP, passes_near_up, transition
from freecad_conformal.paths.assemble import layer_travel
from freecad_conformal.post.linearize import linearize
from freecad_conformal.post.machine import load_machine
from freecad_conformal.toolpath import ToolpathBuilder


def tilted(tilt_deg: float, azimuth_deg: float) -> np.ndarray:
    t, a = math.radians(tilt_deg), math.radians(azimuth_deg)
    return np.array([math.sin(t) * math.cos(a), math.sin(t) * math.sin(a), math.cos(t)])


#: A Y-shaped part's travel from the top of one arm (axis 4° from +Z) to the next arm (its
#: axis nearly along −X): the shortest turn passes 0.13° from +Z.
LEAVING, ARRIVING = tilted(4.0, -1.8), tilted(89.22, 180.0)


def test_a_turn_passing_close_by_up_is_recognised():
    assert passes_near_up(LEAVING, ARRIVING)
    assert passes_near_up(ARRIVING, LEAVING)
    assert not passes_near_up(tilted(4.0, 0.0), tilted(80.0, 180.0))     # through UP itself
    assert not passes_near_up(tilted(10.0, 90.0), tilted(80.0, 180.0))   # nowhere near
    assert passes_near_up(tilted(0.72, -177.2), tilted(0.24, -8.2))      # layers either side
    assert not passes_near_up(tilted(0.5, 10.0), tilted(1.5, 10.0))       # along a meridian
    # the circle comes near UP, but beyond the arc's end
    assert not passes_near_up(tilted(30.0, 0.5), tilted(10.0, 0.5))


def test_near_up_agrees_with_the_sampled_turn():
    """Against the turn itself, sampled: random pairs of axes within 10° of +Z, unequal or
    equal, whose closest approach to +Z is not within a sample's reach of the cone's edge or
    of +Z itself."""
    rng = np.random.default_rng(7)
    seen = {True: 0, False: 0}
    for _ in range(400):
        a = tilted(rng.uniform(0.0, 10.0), rng.uniform(-180.0, 180.0))
        b = a.copy() if rng.uniform() < 0.1 else tilted(rng.uniform(0.0, 10.0),
                                                         rng.uniform(-180.0, 180.0))
        if np.array_equal(a, b):
            assert not passes_near_up(a, b)        # no turn
            continue
        turn = approach.slerp_directions(a, b, 4001, UP)[1:-1]
        closest = math.degrees(math.acos(min(1.0, float(np.max(turn @ UP))))) if len(turn) else 90.0
        ends = min(math.degrees(math.acos(min(1.0, float(e @ UP)))) for e in (a, b))
        if abs(closest - math.degrees(POLE_CONE)) < 0.05 or closest < 1e-3 or closest >= ends - 1e-6:
            continue            # at the cone's edge, through +Z, or nearest at an end
        expected = closest < math.degrees(POLE_CONE)
        assert passes_near_up(a, b) == expected, (a, b, closest)
        seen[expected] += 1
    assert seen[True] > 20 and seen[False] > 20


def post_travel(points: np.ndarray, axes: np.ndarray):
    builder = ToolpathBuilder()
    builder.add_segment(points, axes, kind="travel", feed=6000)
    return linearize(builder.build(), load_machine("trunnion_ac"))


def test_the_travel_turns_through_up_and_posts():
    centre, radius = np.array([0.0, 0.0, 30.0]), 40.0
    end, start = np.array([31.0, 0.95, 60.7]), np.array([-5.25, 0.0, 26.5])
    points, axes = transition(end, LEAVING, start, ARRIVING, centre, radius)
    assert np.any(np.all(axes == UP, axis=1))
    # near UP the axis runs along its ends' meridians (the turntable stands still) and
    # turns about UP only on it
    off = np.arccos(np.clip(axes @ UP, -1.0, 1.0))
    near = axes[(off > 0.0) & (off < POLE_CONE)]
    assert len(near)
    azimuth = np.degrees(np.arctan2(near[:, 1], near[:, 0]))
    assert np.all(np.isclose(azimuth, -1.8, atol=1e-9) | np.isclose(np.abs(azimuth), 180.0, atol=1e-9))
    blocks = post_travel(np.vstack((end, points)), np.vstack((LEAVING, axes)))
    assert len(blocks.joints) > len(points)


def test_the_shortest_turn_past_up_is_what_the_post_refuses(monkeypatch):
    """The case the turn through UP avoids (so this test's fix is the one needed)."""
    monkeypatch.setattr(approach, "passes_near_up", lambda a, b: False)
    centre, radius = np.array([0.0, 0.0, 30.0]), 40.0
    end, start = np.array([31.0, 0.95, 60.7]), np.array([-5.25, 0.0, 26.5])
    points, axes = transition(end, LEAVING, start, ARRIVING, centre, radius)
    with pytest.raises(PostError, match="rotary joints jump"):
        post_travel(np.vstack((end, points)), np.vstack((LEAVING, axes)))


def test_a_new_layer_tilted_to_the_other_side_of_up_is_reached_through_it():
    """Two 3-D layers of a symmetric Y's stem, tilted 0.72° and 0.24° to either side of +Z:
    the rise between them turns the axis on +Z, and the move posts."""
    position, start = np.array([-14.4, -0.58, 7.05]), np.array([-22.11, 0.45, 7.22])
    below, above = tilted(0.724, -177.2), tilted(0.24, -8.2)
    points, axes = layer_travel(position, below, start, above, True)
    assert len(points) == 3 and np.array_equal(axes[0], UP)
    np.testing.assert_allclose(axes[1:], [above, above])
    np.testing.assert_allclose(points[-1], start)
    post_travel(np.vstack((position, points)), np.vstack((below, axes)))
    # layers tilted to one side keep the plain rise
    points, axes = layer_travel(position, tilted(0.7, 10.0), start, above, True)
    assert len(points) == 2 and not np.any(np.all(axes == UP, axis=1))
    with pytest.raises(PostError, match="rotary joints jump"):
        post_travel(np.vstack((position, points[-2:])), np.vstack((below, [above, above])))
