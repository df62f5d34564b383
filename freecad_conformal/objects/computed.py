"""Objects whose work can run away from the document: inputs -> compute -> apply.

A proxy splits its `execute` in three: `inputs(obj)` reads the document into plain values
(shapes in OCC's binary format, numbers and strings for settings), `compute` (objects/work.py) turns
those into plain results without touching any document (so it can run in another process),
and `apply(obj, result)` writes the results into the object's properties. A plain recompute
does all three in a row (headless, macros). The GUI computes in a worker process and hands
the result in with `precompute`; the recompute that follows then only applies it, inside the
command's transaction. A recompute the GUI did not start itself (the property editor, Ctrl+R,
a reopened file) is handed to the GUI through DEFER, which computes it in a worker too.
"""
from __future__ import annotations

import hashlib
import pickle
from contextlib import contextmanager
from typing import Any

from freecad_conformal.errors import ConformalError

#: (document name, object name) -> (fingerprint of the inputs, result or error), kept until
#: the object's next execute: a result computed for other inputs is not applied.
_PRECOMPUTED: dict[tuple[str, str], tuple[str, Any]] = {}


class WorkerFailure(ConformalError):
    """The worker's error, as one line (its traceback goes to the log)."""


def fingerprint(inputs: dict) -> str:
    """A digest of plain inputs: equal inputs give equal digests."""
    return hashlib.sha256(pickle.dumps(inputs, protocol=4)).hexdigest()


def precompute(obj, inputs: dict, outcome: dict) -> None:
    """Hand a worker's outcome ({"result": ...} or {"error": ...}) to the object's next
    execute; it is used only when the object's inputs are still `inputs`."""
    _PRECOMPUTED[(obj.Document.Name, obj.Name)] = (fingerprint(inputs), outcome)


def take_precomputed(obj, inputs: dict) -> dict | None:
    """The outcome handed in for exactly these inputs, or None (compute it here)."""
    stored = _PRECOMPUTED.pop((obj.Document.Name, obj.Name), None)
    if stored is None or stored[0] != fingerprint(inputs):
        return None
    return stored[1]


#: Set by the GUI (gui/background.py): defer(obj, task, inputs) -> True when it has started
#: computing the object elsewhere and will recompute it with the result; None: compute here.
#: objects/ never imports gui/, so the GUI hands this in.
DEFER: list = [None]
#: Depth of `synchronous()` blocks: inside one, recomputes compute in place.
_SYNCHRONOUS = [0]


@contextmanager
def synchronous():
    """Recomputes inside this block compute in place even in the GUI (scripts that read the
    results right after `doc.recompute()`, task panels computing without a worker)."""
    _SYNCHRONOUS[0] += 1
    try:
        yield
    finally:
        _SYNCHRONOUS[0] -= 1


class Computed:
    """Mixin for proxies: TASK names the compute function (objects/work.TASKS)."""

    TASK = ""

    def inputs(self, obj) -> dict:
        raise NotImplementedError(f"{type(self).__name__} must read its inputs")

    def apply(self, obj, result: dict) -> None:
        raise NotImplementedError(f"{type(self).__name__} must apply its result")

    def run(self, obj) -> None:
        """execute's body: the handed-in outcome for these inputs, else computed here."""
        from freecad_conformal.objects.work import compute

        inputs = self.inputs(obj)
        outcome = take_precomputed(obj, inputs)
        if outcome is None:
            defer = DEFER[0]
            if defer is not None and not _SYNCHRONOUS[0] and defer(obj, self.TASK, inputs):
                return            # computed in the background; the last result stays meanwhile
            self.apply(obj, compute(self.TASK, inputs))
        elif "error" in outcome:
            raise WorkerFailure(outcome["error"])
        else:
            self.apply(obj, outcome["result"])


def shape_to_bytes(shape) -> bytes:
    """A shape in OCC's binary format (placement included): how shapes cross to a worker.
    Binary, not BREP text, which rounds reals: a job computed in the GUI then plans the very
    shape the command line reads (geometry/occ_binary.py). Without the triangulations the
    3D view made of it: FreeCAD's `exportBinary` writes none today (0.20.2, and 1.0 on OCCT
    7.8.1: checked), and the worker must mesh as the command line should one start to."""
    from freecad_conformal.geometry.occ_binary import to_binary
    from freecad_conformal.geometry.solids import without_meshes

    return to_binary(without_meshes(shape))


def shape_from_bytes(written):
    """The shape `shape_to_bytes` wrote (BREP text too, as earlier versions wrote it; a shape
    `read_shapes` already read is itself)."""
    if not isinstance(written, (bytes, str)):
        return written
    if isinstance(written, bytes):
        from freecad_conformal.geometry.occ_binary import from_binary

        return from_binary(written)
    from freecad_conformal.freecad_env import import_freecad

    _, Part = import_freecad()
    shape = Part.Shape()
    shape.importBrepFromString(written)
    return shape


def read_shapes(result: dict) -> dict:
    """The result with the shape it carries ("brep", as `shape_to_bytes` wrote it) read
    already: the GUI reads a worker's shapes apart from the recompute that applies them
    (gui/background.py), and `apply` takes either form through `shape_from_bytes`."""
    if isinstance(result.get("brep"), (bytes, str)):
        return {**result, "brep": shape_from_bytes(result["brep"])}
    return result
