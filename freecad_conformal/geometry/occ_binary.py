"""Shapes to and from OCC's binary format (BinTools), for another process.

Binary keeps every real as the 8 bytes it is, so a shape read back is the one written, bit
for bit: a section cut in a worker is then the section this process would have cut, and
nothing needs a round trip to be compared. BREP text does not (its reals are printed with
a limited number of digits): CrankArm's sections, read back from text, moved its G-code in
4,500 lines, so every section used to pass through text wherever it was cut (0.56 s of the
bottle's 3.7 s of layers on one core).

FreeCAD's binding writes and reads binary only through a file: one in shared memory
where the system has it.
"""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

from freecad_conformal.freecad_env import import_freecad

#: Where the files live for the moment of a transfer: memory, not disk, where available.
SHARED_MEMORY = Path("/dev/shm")


def _folder() -> str | None:
    return str(SHARED_MEMORY) if SHARED_MEMORY.is_dir() and os.access(SHARED_MEMORY, os.W_OK) \
        else None


def to_binary(shape) -> bytes:
    """The shape in OCC's binary format."""
    handle, path = tempfile.mkstemp(suffix=".occ", dir=_folder())
    os.close(handle)
    try:
        shape.exportBinary(path)
        return Path(path).read_bytes()
    finally:
        os.unlink(path)


def from_binary(data: bytes):
    """The shape `to_binary` wrote."""
    _, Part = import_freecad()
    handle, path = tempfile.mkstemp(suffix=".occ", dir=_folder())
    try:
        os.write(handle, data)
    finally:
        os.close(handle)
    try:
        shape = Part.Shape()
        shape.importBinary(path)
        return shape
    finally:
        os.unlink(path)


def faces_to_binary(faces: list) -> bytes:
    """Faces as one binary compound (b"" for none)."""
    if not faces:
        return b""
    _, Part = import_freecad()
    return to_binary(Part.Compound(list(faces)))


def faces_from_binary(data: bytes) -> list:
    """The faces `faces_to_binary` wrote, in order."""
    return from_binary(data).Faces if data else []
