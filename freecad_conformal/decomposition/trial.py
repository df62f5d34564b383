"""The `root_direction="auto"` trial plan, run on the second core while the first plans the
part as placed.

Auto plans each solid as placed (+Z) and, when that leaves more overhang than the solid's
best single axis direction, plans it again from that direction. The second plan is only
useful when the part as placed starts with more overhang than that direction (a split can
only lower it), and then both are independent: the trial starts in a child Python
(`child_python.py`) before the first plan and its pieces come back in OCC's binary format
(bit for bit, so the plan is the one this process would make, as in FreeCAD's GUI). If the
first plan is good enough the child is stopped. Without a child (FreeCAD's GUI, one core)
the trial runs after the first plan, as before.
"""
from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

from freecad_conformal.child_python import ChildPython, can_start_child, serve_prepared

if TYPE_CHECKING:  # imported where used: the child must redirect stdout before FreeCAD loads
    from freecad_conformal.decomposition.planner import Piece, Planner

__all__ = ["ANALYTIC_SURFACES", "EarlyTrial", "Trial", "can_start_child", "planned",
           "trial_spec", "worth_a_trial"]

#: Surfaces OCC intersects in closed form; Booleans on the others (B-splines, offsets,
#: revolutions) walk numerically and cost 0.1–1 s each.
ANALYTIC_SURFACES = frozenset({"Plane", "Cylinder", "Cone", "Sphere", "Toroid"})


def worth_a_trial(solid) -> bool:
    """Whether planning `solid` costs enough for a child to pay: starting one (interpreter,
    FreeCAD, the solid) takes ~0.4 s, while a solid of analytic faces plans in well
    under a second (the table: 0.65 s alone, 1.0 s with a child competing for the cores).
    Free-form faces are what make a plan take seconds (CrankArm's arm)."""
    return any(type(face.Surface).__name__ not in ANALYTIC_SURFACES for face in solid.Faces)


class Trial:
    """`planner.pieces(direction)` running in a child Python, started when the Trial is
    made: `prepare()` sends the solid (OCC binary), `plan()` the direction, `result()`
    waits for the pieces, `stop()` ends it (also unasked)."""

    def __init__(self) -> None:
        self._child = ChildPython("freecad_conformal.decomposition.trial")
        self._prepared = False

    @property
    def _process(self):
        return self._child._process

    def prepare(self, written: bytes) -> None:
        """Send the solid as `written` (OCC binary, geometry/occ_binary.py) at once: the
        child reads and meshes it (`prepared`) while this process decides whether to ask
        (the fan's 1.6 s mesh, which the child made after the request)."""
        self._child.ask(written, last=False)
        self._prepared = True

    def plan(self, planner: Planner, direction, written: bytes) -> None:
        """Ask the child for `planner`'s pieces from `direction`, planned on its solid as
        `written` (sent first, unless `prepare` sent it: the child reads the solid, then the
        request)."""
        if not self._prepared:
            self.prepare(written)
        self._child.ask(trial_spec(planner, direction, written))

    def result(self) -> tuple[list[Piece], list[str]] | None:
        """The trial's pieces and notes; None when the child could not plan at all (it
        did not start, or died): the caller then plans here. Re-raises a planning error."""
        answer = self._child.answer()
        if answer is None:
            return None
        ok, value = answer
        if not ok:
            raise value
        from freecad_conformal.decomposition.planner import Piece

        made, notes = value
        return [Piece.from_data(item) for item in made], notes

    def stop(self) -> None:
        """End the trial (its plan is not needed)."""
        self._child.stop()


class EarlyTrial:
    """A solid's trial begun before `decompose` plans it: the plan search first scans the
    whole solid's orientations (the fan: 2.4 s), and the child reads and meshes the solid
    meanwhile. Made where no child can start too (FreeCAD's GUI): the solid's bytes are then
    those `decompose` plans the turned root from in place, as the child would. `decompose`
    takes it for that very solid (`take`); `stop()` ends a child nobody took."""

    def __init__(self, solid) -> None:
        from freecad_conformal.geometry.occ_binary import to_binary

        self._solid = solid
        self.written = to_binary(solid)
        self._trial = None
        if can_start_child():
            self._trial = Trial()
            self._trial.prepare(self.written)

    def take(self, solid) -> tuple[bytes, Trial | None] | None:
        """(the solid as written, its trial: None without a child) when `solid` is the one
        this was begun for or a copy of it in the same place (the plan decomposes the copy
        the placement made: `jobs/placement.turn_up`), else None. The trial is handed over
        once."""
        if not _same_in_place(solid, self._solid):
            return None
        trial, self._trial = self._trial, None
        return self.written, trial

    def stop(self) -> None:
        """End the child if `take` did not hand it over."""
        if self._trial is not None:
            self._trial.stop()
            self._trial = None


def _same_in_place(solid, other) -> bool:
    """Whether `solid` is `other` or a copy of it left where it was: the same faces, edges
    and vertices, the faces on the same kinds of surface and the vertices at the very same
    points (a moved or turned copy, or another solid, differs in some)."""
    if solid.isSame(other):
        return True
    if (len(solid.Faces), len(solid.Edges), len(solid.Vertexes)) != (
            len(other.Faces), len(other.Edges), len(other.Vertexes)):
        return False
    if any(type(a.Surface) is not type(b.Surface) for a, b in zip(solid.Faces, other.Faces)):
        return False
    return all(a.Point == b.Point for a, b in zip(solid.Vertexes, other.Vertexes))


def trial_spec(planner: Planner, direction, written: bytes) -> dict:
    """What a trial plan needs: `planner`'s settings, its solid as `written` (OCC binary),
    the direction."""
    return {"solid": written, "solid_index": planner.solid_index, "angle": planner.angle,
            "method": planner.method, "axis_step": planner.axis_step,
            "budget": planner.budget, "direction": [float(c) for c in direction],
            "envelope": None if planner.envelope is None else dataclasses.astuple(planner.envelope)}


def prepared(written: bytes) -> tuple[bytes, object, float]:
    """(`written`, the solid read from it, its mesh deflection) with the solid meshed as the
    plan meshes it first (`Planner.root_mesh`, at the deflection its box gives before a
    mesh: `BoundBox` reads a triangulation once there is one)."""
    from freecad_conformal.geometry.occ_binary import from_binary
    from freecad_conformal.geometry.surface_mesh import mesh_deflection, surface_mesh

    solid = from_binary(written).Solids[0]
    deflection = mesh_deflection(solid)
    surface_mesh(solid, deflection)
    return written, solid, deflection


def planned(spec: dict, ready: tuple[bytes, object, float] | None = None
            ) -> tuple[list[dict], list[str]]:
    """The pieces (as `Piece.to_data`) and notes `spec` asks for: the child's answer, and
    what the parent makes itself when no child could plan, by the same steps. `ready`:
    what `prepared` made of the solid, used when it is the one `spec` names."""
    import numpy as np

    from freecad_conformal.decomposition.planner import Planner
    from freecad_conformal.geometry.occ_binary import from_binary
    from freecad_conformal.process.tools import Envelope

    deflection = None
    if ready is not None and ready[0] == spec["solid"]:
        _, solid, deflection = ready
    else:
        solid = from_binary(spec["solid"]).Solids[0]
    envelope = None if spec["envelope"] is None else Envelope(*spec["envelope"])
    planner = Planner(solid, spec["solid_index"], spec["angle"], spec["method"],
                      spec["axis_step"], spec["budget"], deflection=deflection, envelope=envelope)
    pieces, notes = planner.pieces(np.array(spec["direction"]))
    return [p.to_data() for p in pieces], notes


def _planned_when_ready(ready: tuple[bytes, object, float], spec: dict):
    return planned(spec, ready)


def _preload() -> None:
    # Loaded before the spec arrives, while the parent is still deciding what to ask.
    from freecad_conformal.decomposition import planner  # noqa: F401
    from freecad_conformal.geometry import occ_binary  # noqa: F401


if __name__ == "__main__":
    serve_prepared(prepared, _planned_when_ready, _preload)
