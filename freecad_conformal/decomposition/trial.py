"""The `root_direction="auto"` trial plan, run on the second core while the first plans the
part as placed.

Auto plans each solid as placed (+Z) and, when that leaves more overhang than the solid's
best single axis direction, plans it again from that direction. The second plan is only
useful when the part as placed starts with more overhang than that direction (a split can
only lower it), and then both are independent: the trial starts in a child Python before
the first plan and its pieces come back in OCC's binary format (geometry/occ_binary.py: bit
for bit, so the plan is the one this process would make, as in FreeCAD's GUI). If the first
plan is good enough the child is stopped.

The child is a fresh interpreter (`python -m freecad_conformal.decomposition.trial`), not a fork:
OCC's thread pool, once started in the parent, deadlocks a forked child in its next Boolean
(seen in `generalFuse` under pytest). It is used only outside FreeCAD's GUI and with two or
more cores; otherwise the trial runs after the first plan, as before.
"""
from __future__ import annotations

import os
import pickle
import subprocess
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from freecad_conformal.freecad_env import import_freecad

if TYPE_CHECKING:  # imported where used: the child must redirect stdout before FreeCAD loads
    from freecad_conformal.decomposition.planner import Piece, Planner

#: The folder holding the freecad_conformal package, for the child's import path.
PACKAGE_ROOT = Path(__file__).resolve().parents[2]


#: Surfaces OCC intersects in closed form; Booleans on the others (B-splines, offsets,
#: revolutions) walk numerically and cost 0.1–1 s each.
ANALYTIC_SURFACES = frozenset({"Plane", "Cylinder", "Cone", "Sphere", "Toroid"})


def worth_a_trial(solid) -> bool:
    """Whether planning `solid` costs enough for a child to pay: starting one (interpreter,
    FreeCAD, the solid) takes ~0.4 s, while a solid of analytic faces plans in well
    under a second (the table: 0.65 s alone, 1.0 s with a child competing for the cores).
    Free-form faces are what make a plan take seconds (CrankArm's arm)."""
    return any(type(face.Surface).__name__ not in ANALYTIC_SURFACES for face in solid.Faces)


def can_start_child() -> bool:
    """Whether a trial may run in a child process here."""
    if (os.cpu_count() or 1) < 2:
        return False
    if not Path(sys.executable).name.lower().startswith("python"):
        return False  # embedded (FreeCADCmd): no interpreter to start the child with
    App, _ = import_freecad()
    return not getattr(App, "GuiUp", False)


class Trial:
    """`planner.pieces(direction)` running in a child Python. The child starts (interpreter,
    FreeCAD, this package) when the Trial is made, so that it is ready by the time the
    parent knows which direction to ask for: `plan()` sends the solid (OCC binary) and the
    direction, `result()` waits for the pieces, `stop()` ends it (also unasked)."""

    def __init__(self) -> None:
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join(
            [str(PACKAGE_ROOT)] + ([env["PYTHONPATH"]] if env.get("PYTHONPATH") else []))
        try:
            self._process = subprocess.Popen(
                [sys.executable, "-m", "freecad_conformal.decomposition.trial"],
                stdin=subprocess.PIPE, stdout=subprocess.PIPE, env=env)
        except OSError:
            self._process = None  # no interpreter to start: result() says so

    def plan(self, planner: Planner, direction, written: bytes) -> None:
        """Ask the child for `planner`'s pieces from `direction`, planned on its solid as
        `written` (OCC binary, geometry/occ_binary.py)."""
        if self._process is None:
            return
        try:
            self._process.stdin.write(pickle.dumps(trial_spec(planner, direction, written)))
        except OSError:
            pass  # the child died at once (BrokenPipe): result() sees its exit code
        try:
            self._process.stdin.close()
        except OSError:
            pass  # same: nothing left to flush to

    def result(self) -> tuple[list[Piece], list[str]] | None:
        """The trial's pieces and notes; None when the child could not plan at all (it
        did not start, or died): the caller then plans here. Re-raises a planning error."""
        if self._process is None:
            return None
        data = self._process.stdout.read()
        self._process.stdout.close()
        code = self._process.wait()
        if code != 0 or not data:
            return None
        try:
            ok, payload, notes = pickle.loads(data)
        except (pickle.UnpicklingError, EOFError, AttributeError, ImportError):
            return None
        if not ok:
            raise payload
        from freecad_conformal.decomposition.planner import Piece

        return [Piece.from_data(item) for item in payload], notes

    def stop(self) -> None:
        """End the trial (its plan is not needed)."""
        if self._process is None:
            return
        if self._process.poll() is None:
            self._process.kill()
        for stream in (self._process.stdin, self._process.stdout):
            try:
                stream.close()
            except OSError:
                pass  # a pipe the killed child left unread
        self._process.wait()


def trial_spec(planner: Planner, direction, written: bytes) -> dict:
    """What a trial plan needs: `planner`'s settings, its solid as `written` (OCC binary),
    the direction."""
    return {"solid": written, "solid_index": planner.solid_index, "angle": planner.angle,
            "method": planner.method, "axis_step": planner.axis_step,
            "budget": planner.budget, "direction": [float(c) for c in direction]}


def planned(spec: dict) -> tuple[list[dict], list[str]]:
    """The pieces (as `Piece.to_data`) and notes `spec` asks for: the child's answer, and
    what the parent makes itself when no child could plan, by the same steps."""
    import numpy as np

    from freecad_conformal.decomposition.planner import Planner
    from freecad_conformal.geometry.occ_binary import from_binary

    solid = from_binary(spec["solid"]).Solids[0]
    planner = Planner(solid, spec["solid_index"], spec["angle"], spec["method"],
                      spec["axis_step"], spec["budget"])
    pieces, notes = planner.pieces(np.array(spec["direction"]))
    return [p.to_data() for p in pieces], notes


def _child() -> None:
    """Child side: read the spec on stdin, plan, write (ok, pieces or error, notes)."""
    out = os.fdopen(os.dup(1), "wb")
    os.dup2(2, 1)  # anything FreeCAD prints goes to stderr, not into the result stream
    # Loaded before the spec arrives, while the parent is still deciding what to ask.
    from freecad_conformal.decomposition import planner  # noqa: F401
    from freecad_conformal.geometry import occ_binary  # noqa: F401

    try:
        spec = pickle.load(sys.stdin.buffer)
    except EOFError:
        return  # not needed after all
    try:
        result = (True, *planned(spec))
    except Exception as exc:  # sent to the parent, which raises it
        from freecad_conformal.errors import ConformalError, GeometryError

        error = exc if isinstance(exc, ConformalError) else GeometryError(
            f"trial plan failed: {type(exc).__name__}: {exc}")
        result = (False, error, [])
    pickle.dump(result, out)
    out.close()


if __name__ == "__main__":
    _child()
