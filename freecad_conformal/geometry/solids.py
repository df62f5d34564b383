"""Loading shapes and checking that they are valid solids, with errors a user understands."""
from __future__ import annotations

import logging
import os
import sys
import threading
from contextlib import contextmanager
from pathlib import Path

from freecad_conformal.errors import GeometryError
from freecad_conformal.freecad_env import import_freecad, make_workbench_types_loadable
from freecad_conformal.geometry.shape_cache import ShapeCache

#: File suffixes `load_shape` reads, lower case.
SHAPE_SUFFIXES = (".step", ".stp", ".brep", ".brp", ".iges", ".igs", ".fcstd")
#: Warnings about inputs the loader repaired or skipped (the CLI prints them as "warning: ...").
LOG = logging.getLogger("freecad_conformal")
#: Seconds a file may spend in FreeCAD's reader before the command gives up (None: wait).
#: Set by the command line only: a corrupt file can keep OCC's reader busy for minutes,
#: where Ctrl-C does not reach it, and the only way out of a C++ call is ending the process,
#: which a FreeCAD session must never do.
READ_TIME_LIMIT: list[float | None] = [None]
#: Exit code of a command stopped by the reading watchdog.
READ_TIMEOUT_EXIT = 1


def load_shape(path: str | os.PathLike):
    """Read a STEP, BREP, IGES or FCStd file into one Part.Shape (FCStd: its solid bodies)."""
    App, Part = import_freecad()
    file = Path(path)
    if not file.is_file():
        raise GeometryError(f"part file not found: {file}")
    suffix = file.suffix.lower()
    if suffix not in SHAPE_SUFFIXES:
        raise GeometryError(
            f"cannot read {file.name}: suffix {suffix!r} is not one of {', '.join(SHAPE_SUFFIXES)}")
    if file.stat().st_size == 0:
        raise GeometryError(f"{file.name} is empty (0 bytes)")
    _check_step_header(file, suffix)
    with reading_watchdog(file):
        if suffix == ".fcstd":
            return without_meshes(_load_fcstd(App, Part, file))
        try:
            shape = Part.read(str(file))
        except Exception as exc:  # OCC reader errors are plain Exceptions with terse text
            raise GeometryError(f"cannot read {file.name}: {exc}; the file may be damaged "
                                "(repair or re-export it)") from exc
    if shape.isNull():
        raise GeometryError(f"{file.name} holds no shape")
    if not shape.Solids and shape.Faces:
        shape = _sewn_solids(Part, shape, file.name)
    loose = loose_tolerance(shape)
    if loose:
        LOG.warning("%s: %s; sections and cuts may fail or merge loops (repair it: Part > "
                    "Check geometry, rebuild the Boolean that made it, or re-export it)",
                    file.name, loose)
    return without_meshes(shape) if suffix in MESH_CARRYING_SUFFIXES else shape


#: A tolerance (mm) above this on a vertex, edge or face makes OCC take points that close as
#: one: at a quarter of the bead width, planes near such a vertex may come back empty or
#: loops merge. A Boolean with a degenerate operand left 13 mm on a 4 mm rod, whose sections
#: near its top then failed every way; the real parts here carry at most 0.016 mm (the bottle).
LOOSE_TOLERANCE = 0.1


def loose_tolerance(shape) -> str:
    """What of `shape` carries a tolerance above LOOSE_TOLERANCE ("a vertex carries a
    tolerance of 13 mm"), or "" where none does."""
    _, Part = import_freecad()
    for kind, name in ((Part.Vertex, "vertex"), (Part.Edge, "edge"), (Part.Face, "face")):
        tolerance = shape.getTolerance(1, kind)
        if tolerance > LOOSE_TOLERANCE:
            return f"a {name} carries a tolerance of {tolerance:.3g} mm (OCC takes points that close as one)"
    return ""


#: A STEP file begins with this (ISO 10303-21), after at most a byte-order mark and blanks.
STEP_MAGIC = b"ISO-10303-21;"


def _check_step_header(file: Path, suffix: str) -> None:
    """A file named .step/.stp that is not one (another format renamed, a text saved under
    that name) is said to be so: OCC's reader only says "Error in reading STEP"."""
    if suffix not in (".step", ".stp"):
        return
    with open(file, "rb") as handle:
        head = handle.read(256).lstrip(b"\xef\xbb\xbf").lstrip()
    if not head.startswith(STEP_MAGIC):
        raise GeometryError(f"{file.name} is not a STEP file: it does not begin with "
                            f"{STEP_MAGIC.decode()!r} (another format renamed {suffix}?)")


#: Formats that may store triangulations with the geometry (BREP; FreeCAD documents hold BREP).
MESH_CARRYING_SUFFIXES = (".brep", ".brp", ".fcstd")


def without_meshes(shape):
    """A copy of the shape without the triangulations its file stored or FreeCAD's 3D view
    made. OCC reads a triangulated shape's `BoundBox` from them, and BRepMesh keeps a finer
    one than asked: the plan read its placement on the platform and its mesh deflection from
    that box (Pump_Nut's, 3.4 mm narrower than the box of its geometry alone, moved its
    G-code) and its overhangs from that mesh (a document object's shape as a macro passes
    it, meshed for the view). Without them every caller plans the same."""
    return shape.cleaned()


@contextmanager
def reading_watchdog(file: Path):
    """Within READ_TIME_LIMIT seconds the block ends, or the process does, with an error
    line naming the file (nothing has been written yet while a part is being read)."""
    limit = READ_TIME_LIMIT[0]
    if limit is None:
        yield
        return

    def give_up() -> None:
        sys.stderr.write(f"error: reading {file.name} took longer than {limit:g} s; the file "
                         "may be damaged (repair or re-export it)\n")
        sys.stderr.flush()
        os._exit(READ_TIMEOUT_EXIT)

    timer = threading.Timer(limit, give_up)
    timer.daemon = True
    timer.start()
    try:
        yield
    finally:
        timer.cancel()


def _sewn_solids(Part, shape, name: str):
    """Faces with no solid (an IGES of trimmed surfaces, a STEP of a shell) sewn into solids
    where they close; the shape unchanged (and refused later, by name) where they do not."""
    sewn = shape.copy()
    sewn.sewShape()
    solids = []
    for shell in sewn.Shells:
        if not shell.isClosed():
            continue
        solid = Part.Solid(shell)
        if solid.Volume < 0:
            solid.reverse()
        if solid.isValid() and solid.Volume > 0:
            solids.append(solid)
    if not solids:
        return shape
    LOG.warning("%s holds faces but no solid: sewed %d face(s) into %d closed solid(s)",
                name, len(shape.Faces), len(solids))
    return Part.Compound(solids) if len(solids) > 1 else solids[0]


def _load_fcstd(App, Part, file: Path):
    make_workbench_types_loadable()
    try:
        doc = App.openDocument(str(file), True)
    except Exception as exc:  # a damaged archive or document.xml: FreeCAD's own message
        raise GeometryError(f"cannot read {file.name}: not a readable FreeCAD document ({exc})") \
            from exc
    try:
        solids = []
        for obj in doc.Objects:
            shape = getattr(obj, "Shape", None)
            if shape is None or shape.isNull() or not shape.Solids:
                continue
            # Only objects at the top of the tree: features consumed by others are not parts.
            if any(parent for parent in obj.InList if getattr(parent, "Shape", None) is not None):
                continue
            solids.extend(shape.Solids)
        if not solids:
            raise GeometryError(f"{file.name} holds no solid body")
        return Part.Compound(solids) if len(solids) > 1 else solids[0]
    finally:
        App.closeDocument(doc.Name)


#: Whether OCC's check passed, by solid identity: a job checks the part, then cuts rigid
#: copies of it (centred, turned, laid out), and each cut checked its copy again (12 ms a
#: copy of Pump_Nut, four copies a plan).
_CHECKED: ShapeCache[bool] = ShapeCache(limit=4096, oriented=True)


def moved_rigidly(original, copy) -> None:
    """Record that `copy` is `original` copied and then only rotated or translated: OCC's
    check would find of it what it found of the original (a rigid motion changes no
    distance or tolerance it compares), so `solids_of` does not check it again; and its
    faces' and edges' boxes are the original's moved (`boxes.seed_moved_boxes`), and so is
    its mesh where one was made (`surface_mesh.seed_moved_mesh`, for the collision samples)."""
    from freecad_conformal.geometry.boxes import seed_moved_boxes
    from freecad_conformal.geometry.surface_mesh import seed_moved_mesh

    seed_moved_boxes(original, copy)
    seed_moved_mesh(original, copy)
    for solid, twin in zip(original.Solids, copy.Solids):
        known = _CHECKED.peek((solid,))
        if known is not None:
            _CHECKED.get((twin,), lambda known=known: known)


def checked_elsewhere(solid) -> None:
    """Record that `solid` passed OCC's check in another process (a worker's copy, read
    from OCC's binary format, of a solid its parent checked)."""
    _CHECKED.get((solid,), lambda: True)


def solids_of(shape, what: str = "shape") -> list:
    """The solids of `shape`, checked: a GeometryError names a null, invalid or solid-less input."""
    App, Part = import_freecad()
    if shape is None or not isinstance(shape, Part.Shape):
        raise GeometryError(f"{what} is not a Part shape (got {type(shape).__name__})")
    if shape.isNull():
        raise GeometryError(f"{what} is empty (null shape)")
    solids = list(shape.Solids)
    empty = [i for i, solid in enumerate(solids) if not solid.Faces]
    if empty and len(empty) < len(solids):
        LOG.warning("%s: skipped %d empty solid(s) (no faces): %s", what, len(empty),
                    ", ".join(f"solid {i + 1} of {len(solids)}" for i in empty))
        solids = [solid for i, solid in enumerate(solids) if i not in empty]
    if not solids:
        kind = shape.ShapeType
        if kind == "Shell":
            hint = " (a closed shell can be made a solid with Part.Solid(shell))"
        elif kind == "Compound" and shape.Faces:
            # IGES files often hold a solid's faces only (FreeCAD 0.20's own IGES export
            # does), and sewing them (`load_shape`) closes no shell where a face's edges
            # miss its neighbours' (a bore's B-spline circles against the end faces' arcs).
            hint = (f", only {len(shape.Faces)} faces that do not close into one (a surface "
                    "model, as IGES files often hold: export the part as STEP, or make it a "
                    "solid in FreeCAD: Part > Shape builder, shell from faces, then solid "
                    "from shell)")
        else:
            hint = ""
        article = "an" if kind[:1] in "AEIOU" else "a"
        raise GeometryError(f"{what} is not a solid: it is {article} {kind} with no solids{hint}")
    for index, solid in enumerate(solids):
        if not passes_check(solid):
            raise GeometryError(f"{what}: solid {index + 1} of {len(solids)} is invalid "
                                f"(OCC check failed; try Part > Check geometry / refine)")
        if not solid.Faces:
            raise GeometryError(f"{what}: solid {index + 1} of {len(solids)} is empty (no faces)")
        if solid.Volume <= 0:
            raise GeometryError(f"{what}: solid {index + 1} of {len(solids)} has non-positive "
                                f"volume {solid.Volume:.6g} mm³ (reversed orientation?)")
    return solids


def passes_check(solid) -> bool:
    """OCC's check of the solid, made once per solid (and its rigid copies: `moved_rigidly`)."""
    return _CHECKED.get((solid,), solid.isValid)


def occ_confusion() -> float:
    """OpenCASCADE's confusion distance (Precision::Confusion, mm): points closer than this
    are one point for OCC, so no geometric test here can be finer."""
    _, Part = import_freecad()
    return float(Part.Precision.confusion())


#: Solids of one part sharing more than this volume (mm³) are one body to print: built
#: apart they could never be put together. Touching solids (a shared face, a pin in a bore)
#: share none, to OCC's rounding (1e-9 mm³ on two boxes sharing a face).
OVERLAP_VOLUME = 1e-3


def united_overlaps(shape) -> tuple[object, str]:
    """`shape` with each group of its overlapping solids fused into one solid, as a slicer
    prints the overlapping parts of one object, and a note saying which ("" where none
    overlap). A multi-body export with a boss modelled as its own body overlapping the base
    was laid out as two parts side by side."""
    _, Part = import_freecad()
    solids = list(shape.Solids)
    if len(solids) < 2:
        return shape, ""
    group = list(range(len(solids)))

    def root(k: int) -> int:
        while group[k] != k:
            k = group[k]
        return k

    shared = []
    for i, first in enumerate(solids):
        for j in range(i + 1, len(solids)):
            if not first.BoundBox.intersect(solids[j].BoundBox):
                continue
            volume = first.common(solids[j]).Volume
            if volume > OVERLAP_VOLUME:
                group[root(j)] = root(i)
                shared.append((i, j, volume))
    if not shared:
        return shape, ""
    members: dict[int, list[int]] = {}
    for k in range(len(solids)):
        members.setdefault(root(k), []).append(k)
    united = []
    for ks in members.values():
        if len(ks) == 1:
            united.append(solids[ks[0]])
            continue
        fused = solids[ks[0]].fuse([solids[k] for k in ks[1:]]).removeSplitter()
        if len(fused.Solids) != 1:
            raise GeometryError(f"solids {_numbers(ks)} overlap but do not fuse into one solid "
                                "(OCC); fuse them in the model (Part > Boolean > Union)")
        united.append(fused.Solids[0])
    pairs = "; ".join(f"{i + 1} and {j + 1} by {volume:.3g} mm³" for i, j, volume in shared)
    note = (f"solids overlap ({pairs}): each overlapping group fused into one solid, as a "
            f"slicer prints an object's overlapping parts ({len(solids)} solids -> {len(united)})")
    return (united[0] if len(united) == 1 else Part.makeCompound(united)), note


def _numbers(indices: list[int]) -> str:
    return ", ".join(str(k + 1) for k in indices)


def enclosed_cavities(solid) -> list[float]:
    """Volumes (mm³) of the closed voids inside `solid`: its shells besides the outer one.
    A void's highest point faces down whatever the build direction, so its ceiling needs
    support in every plan, and support inside it could never be taken out."""
    shells = solid.Shells
    if len(shells) < 2:
        return []
    _, Part = import_freecad()
    outer = solid.OuterShell
    return [abs(Part.Solid(shell).Volume) for shell in shells if not shell.isSame(outer)]


def cavities_note(solids: list) -> str | None:
    """What a user should know of the part's closed voids (None when there are none)."""
    found = [(number, enclosed_cavities(solid)) for number, solid in enumerate(solids, start=1)]
    found = [(number, volumes) for number, volumes in found if volumes]
    if not found:
        return None
    which = "; ".join(
        f"solid {number}: {len(volumes)} closed cavit{'y' if len(volumes) == 1 else 'ies'} "
        f"of {sum(volumes) / 1000:.3g} cm3" for number, volumes in found)
    return (f"{which}: a closed cavity's ceiling faces down whatever the build direction, "
            "so no plan builds it support-free and its overhang is left (printed over the "
            "void, as a bridge if it holds); support inside could not be taken out. Open "
            "the cavity to the outside, or model the part as two pieces parted at it, to "
            "build it support-free")
