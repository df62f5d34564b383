"""Loading shapes and checking that they are valid solids, with errors a user understands."""
from __future__ import annotations

import os
from pathlib import Path

from freecad_conformal.errors import GeometryError
from freecad_conformal.freecad_env import import_freecad, make_workbench_types_loadable

#: File suffixes `load_shape` reads, lower case.
SHAPE_SUFFIXES = (".step", ".stp", ".brep", ".brp", ".iges", ".igs", ".fcstd")


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
    if suffix == ".fcstd":
        return _load_fcstd(App, Part, file)
    try:
        shape = Part.read(str(file))
    except Exception as exc:  # OCC reader errors are plain Exceptions with terse text
        raise GeometryError(f"cannot read {file.name}: {exc}") from exc
    if shape.isNull():
        raise GeometryError(f"{file.name} holds no shape")
    return shape


def _load_fcstd(App, Part, file: Path):
    make_workbench_types_loadable()
    doc = App.openDocument(str(file), True)
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
        return Part.makeCompound(solids) if len(solids) > 1 else solids[0]
    finally:
        App.closeDocument(doc.Name)


def solids_of(shape, what: str = "shape") -> list:
    """The solids of `shape`, checked: a GeometryError names a null, invalid or solid-less input."""
    App, Part = import_freecad()
    if shape is None or not isinstance(shape, Part.Shape):
        raise GeometryError(f"{what} is not a Part shape (got {type(shape).__name__})")
    if shape.isNull():
        raise GeometryError(f"{what} is empty (null shape)")
    solids = list(shape.Solids)
    if not solids:
        kind = shape.ShapeType
        hint = " (a closed shell can be made a solid with Part.Solid(shell))" if kind == "Shell" else ""
        raise GeometryError(f"{what} is not a solid: it is a {kind} with no solids{hint}")
    for index, solid in enumerate(solids):
        if not solid.isValid():
            raise GeometryError(f"{what}: solid {index + 1} of {len(solids)} is invalid "
                                f"(OCC check failed; try Part > Check geometry / refine)")
        if solid.Volume <= 0:
            raise GeometryError(f"{what}: solid {index + 1} of {len(solids)} has non-positive "
                                f"volume {solid.Volume:.6g} mm³ (reversed orientation?)")
    return solids


def occ_confusion() -> float:
    """OpenCASCADE's confusion distance (Precision::Confusion, mm): points closer than this
    are one point for OCC, so no geometric test here can be finer."""
    _, Part = import_freecad()
    return float(Part.Precision.confusion())
