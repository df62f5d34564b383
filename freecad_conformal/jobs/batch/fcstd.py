"""Every solid body of a FreeCAD document as a separate part.

A body is a top-level object whose Shape holds solids: a PartDesign::Body, a Part::Feature,
a Part boolean... Features consumed by another shape-bearing object (a Pad inside its Body,
the tools of a Part::Cut) are steps towards a part, not parts, so they are skipped.
"""
from __future__ import annotations

import os
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator

from freecad_conformal.errors import GeometryError
from freecad_conformal.freecad_env import import_freecad, make_workbench_types_loadable


@dataclass(frozen=True)
class Body:
    """One solid body of a document: its internal `name` (unique, used to find it again)
    and the `label` the user sees in the tree."""

    name: str
    label: str


@contextmanager
def open_document(path: str | os.PathLike) -> Iterator[object]:
    """The document at `path`, opened hidden and closed afterwards (unless it was open)."""
    App, _Part = import_freecad()
    file = Path(path)
    if not file.is_file():
        raise GeometryError(f"FreeCAD document not found: {file}")
    already_open = _open_document_of(App, file)
    if already_open is not None:
        yield already_open
        return
    make_workbench_types_loadable()
    try:
        doc = App.openDocument(str(file), True)
    except Exception as exc:  # FreeCAD raises plain Exceptions (bad zip, bad XML)
        raise GeometryError(f"cannot open FreeCAD document {file.name}: {exc}") from exc
    try:
        yield doc
    finally:
        App.closeDocument(doc.Name)


def _open_document_of(App, file: Path):
    """The document already open from `file` (in the GUI), or None. It is read as it is in
    memory and left open: closing it would throw away the user's unsaved work."""
    for doc in App.listDocuments().values():
        name = getattr(doc, "FileName", "")
        if name and os.path.exists(name) and os.path.samefile(name, file):
            return doc
    return None


def _is_solid_body(obj) -> bool:
    shape = getattr(obj, "Shape", None)
    if shape is None or shape.isNull() or not shape.Solids:
        return False
    # Only objects at the top of the tree: features consumed by others are not parts.
    return not any(getattr(parent, "Shape", None) is not None for parent in obj.InList)


def solid_bodies(path: str | os.PathLike) -> list[Body]:
    """The solid bodies of the document at `path`, in tree order.

    Raises GeometryError when the document cannot be opened or holds no solid body.
    """
    with open_document(path) as doc:
        bodies = [Body(obj.Name, obj.Label) for obj in doc.Objects if _is_solid_body(obj)]
    if not bodies:
        raise GeometryError(f"{Path(path).name} holds no solid body")
    return bodies


def body_shape(path: str | os.PathLike, name: str):
    """A copy of the shape of body `name` (internal name) in the document at `path`.

    The copy outlives the document, which is closed before returning.
    """
    with open_document(path) as doc:
        obj = doc.getObject(name)
        if obj is None:
            raise GeometryError(f"{Path(path).name} has no object named {name!r}")
        if not _is_solid_body(obj):
            raise GeometryError(f"{Path(path).name}: {obj.Label!r} is not a solid body")
        return obj.Shape.copy()
