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


def l_block(column: float = 10.0, height: float = 40.0, arm: float = 30.0,
            thickness: float = 10.0, depth: float = 20.0):
    """An upside-down L: a column on the bed and an arm overhanging sideways (+X) at its top.

    Built upright the arm's underside needs support; split at the column's side it builds
    horizontally (+X) from the column.
    """
    App, Part = import_freecad()
    V = App.Vector
    stem = Part.makeBox(column, depth, height)
    bar = Part.makeBox(arm, depth, thickness, V(column, 0, height - thickness))
    return stem.fuse(bar).removeSplitter().Solids[0]


def t_block(stem: float = 10.0, height: float = 40.0, arm: float = 25.0,
            thickness: float = 10.0, depth: float = 20.0):
    """A T: a stem on the bed centred on x = 0 with arms of length `arm` in +X and −X."""
    App, Part = import_freecad()
    V = App.Vector
    half = stem / 2
    column = Part.makeBox(stem, depth, height, V(-half, 0, 0))
    bar = Part.makeBox(stem + 2 * arm, depth, thickness, V(-half - arm, 0, height - thickness))
    return column.fuse(bar).removeSplitter().Solids[0]


def inclined_rod(tilt_deg: float = 30.0, radius: float = 5.0, length: float = 40.0,
                 base: float = 40.0, base_height: float = 8.0):
    """A round rod tilted `tilt_deg` from +Z towards +X, standing on a square base plate."""
    import math

    App, Part = import_freecad()
    V = App.Vector
    plate = Part.makeBox(base, base, base_height, V(-base / 2, -base / 2, 0))
    tilt = math.radians(tilt_deg)
    axis = V(math.sin(tilt), 0, math.cos(tilt))
    # Start the rod a little inside the plate so the fused solid has no gap under its rim.
    start = V(0, 0, base_height - radius * math.sin(tilt) - 0.5)
    rod = Part.makeCylinder(radius, length, start, axis)
    return plate.fuse(rod).removeSplitter().Solids[0]


def hinge(width: float = 60.0, wall: float = 10.0, height: float = 40.0,
          knuckle: float = 15.0, reach: float = 40.0, thickness: float = 10.0,
          lug_drop: float = 15.0, lug_depth: float = 10.0):
    """A hinge-like part (METHODS section 3): a wall on the bed, two knuckles reaching out
    in +Y at its top, and a lug hanging down (−Z) under each knuckle's end.

    Support-free plan: the wall first (+Z), the knuckles after turning the part 90° about X
    (build direction +Y), the lugs after turning it 180° about Y (build direction −Z).
    """
    App, Part = import_freecad()
    V = App.Vector
    body = Part.makeBox(width, wall, height)
    top = height - thickness
    pieces = []
    for x in (0.0, width - knuckle):
        pieces.append(Part.makeBox(knuckle, reach, thickness, V(x, wall, top)))
        pieces.append(Part.makeBox(knuckle, lug_depth, lug_drop,
                                   V(x, wall + reach - lug_depth, top - lug_drop)))
    return body.fuse(pieces).removeSplitter().Solids[0]


SAMPLES.update({"l_block": l_block, "t_block": t_block, "inclined_rod": inclined_rod,
                "hinge": hinge})


def cross_hole_block(length: float = 30.0, width: float = 20.0, height: float = 16.0,
                     hole: float = 6.0):
    """A block with a round through hole across the build direction (along X): built along
    +Z its ceiling overhangs, so a hybrid plan fills it and cuts it out afterwards."""
    App, Part = import_freecad()
    V = App.Vector
    block = Part.makeBox(length, width, height)
    bore = Part.makeCylinder(hole / 2, length, V(0, width / 2, height / 2), V(1, 0, 0))
    return block.cut(bore).removeSplitter().Solids[0]


def nozzle(diameter: float = 12.0, height: float = 10.0, bore: float = 0.5):
    """A round nozzle with a `bore` mm hole along its axis: too small to deposit round, so
    a hybrid plan fills it and cuts it layer by layer (METHODS section 6's nozzle)."""
    App, Part = import_freecad()
    body = Part.makeCylinder(diameter / 2, height)
    return body.cut(Part.makeCylinder(bore / 2, height)).removeSplitter().Solids[0]


def branch45(block: tuple[float, float, float] = (40.0, 30.0, 10.0), branch: float = 10.0,
             length: float = 30.0, lean_deg: float = 45.0):
    """A block with a square branch leaning `lean_deg` from vertical (METHODS section 6's
    45° example): planar layers along +Z leave the branch's underside at the overhang limit."""
    App, Part = import_freecad()
    V = App.Vector
    base = Part.makeBox(*block)
    arm = Part.makeBox(branch, branch, length, V(-branch / 2, -branch / 2, 0))
    arm.rotate(V(0, 0, 0), V(0, 1, 0), lean_deg)
    arm.translate(V(0.3 * block[0], block[1] / 2, block[2]))
    solid = base.fuse(arm).common(Part.makeBox(1e3, 1e3, 1e3, V(-500, -500, 0)))
    return solid.removeSplitter().Solids[0]


def domed_cylinder(radius: float = 10.0, height: float = 10.0):
    """A cylinder under a hemispherical dome: planar layers leave the dome stepped, so a
    hybrid plan finishes it with a ball end mill."""
    App, Part = import_freecad()
    body = Part.makeCylinder(radius, height)
    dome = Part.makeSphere(radius, App.Vector(0, 0, height))
    above = Part.makeBox(4 * radius, 4 * radius, 2 * radius + height,
                         App.Vector(-2 * radius, -2 * radius, 0))
    return body.fuse(dome).common(above).removeSplitter().Solids[0]


def oblique_prism(side: float = 15.0, tilt_deg: float = 20.0, shift: float = 3.0,
                  rise: float = 8.0, sections: int = 6):
    """Squares in planes tilted `tilt_deg` about X, each `shift` mm further along X and
    `rise` higher, lofted: its four sides are planes written as B-spline surfaces, as lofts
    and exporters write them. Support-free standing on an end or lying on a side."""
    import math

    App, Part = import_freecad()
    V = App.Vector
    tilt, half = math.radians(tilt_deg), side / 2
    wires = []
    for k in range(sections):
        corners = [V(x + shift * k, y * math.cos(tilt), rise * k + y * math.sin(tilt))
                   for x, y in ((-half, -half), (half, -half), (half, half), (-half, half))]
        wires.append(Part.makePolygon(corners + [corners[0]]))
    return Part.makeLoft(wires, True, False).Solids[0]


SAMPLES.update({"cross_hole_block": cross_hole_block, "nozzle": nozzle, "branch45": branch45,
                "domed_cylinder": domed_cylinder, "oblique_prism": oblique_prism})


#: Names a built-in sample explicitly (`sample:jack`), even when a file of that name exists.
SAMPLE_PREFIX = "sample:"


def load_part(text: str):
    """(shape, name) of a part file (STEP, BREP, IGES, FCStd), of `sample:NAME`, or of a bare
    sample name when no file of that name exists (so `plan jack` works from any folder)."""
    from pathlib import Path

    from freecad_conformal.errors import GeometryError
    from freecad_conformal.geometry.solids import load_shape

    name = text[len(SAMPLE_PREFIX):] if text.startswith(SAMPLE_PREFIX) else None
    if name is None and not Path(text).exists() and text in SAMPLES:
        name = text
    if name is not None:
        if name not in SAMPLES:
            raise GeometryError(f"no sample part {name!r} (known: {', '.join(sorted(SAMPLES))})")
        return SAMPLES[name](), name
    return load_shape(text), Path(text).stem
