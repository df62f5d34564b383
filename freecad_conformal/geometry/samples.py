"""Sample parts the project builds itself (demo, tests, benchmarks): exact B-rep solids."""
from __future__ import annotations

from freecad_conformal.freecad_env import import_freecad


def overhang_bracket():
    """A 40 × 30 × 10 mm base with a 10 mm column and a 30 mm arm overhanging it, plus a hole.

    Printed upright on a planar machine the arm needs support over its whole underside;
    split at the arm's root face it builds support-free in two directions.
    """
    App, Part = import_freecad()
    V = App.Vector
    base = Part.makeBox(40, 30, 10)
    column = Part.makeBox(10, 30, 40, V(0, 0, 10))
    arm = Part.makeBox(30, 30, 10, V(10, 0, 40))
    hole = Part.makeCylinder(5, 10, V(25, 15, 0))
    solid = base.fuse([column, arm]).cut(hole).removeSplitter()
    return solid.Solids[0]


def jack(cube: float = 12.0, arm_length: float = 25.0, arm_width: float = 8.0):
    """A cube with six square arms along ±X, ±Y, ±Z: it needs support in every orientation."""
    App, Part = import_freecad()
    V = App.Vector
    half = cube / 2
    body = Part.makeBox(cube, cube, cube, V(-half, -half, -half))
    w = arm_width / 2
    arms = [
        Part.makeBox(arm_length, arm_width, arm_width, V(half, -w, -w)),
        Part.makeBox(arm_length, arm_width, arm_width, V(-half - arm_length, -w, -w)),
        Part.makeBox(arm_width, arm_length, arm_width, V(-w, half, -w)),
        Part.makeBox(arm_width, arm_length, arm_width, V(-w, -half - arm_length, -w)),
        Part.makeBox(arm_width, arm_width, arm_length, V(-w, -w, half)),
        Part.makeBox(arm_width, arm_width, arm_length, V(-w, -w, -half - arm_length)),
    ]
    return body.fuse(arms).removeSplitter().Solids[0]


SAMPLES = {"bracket": overhang_bracket, "jack": jack}
