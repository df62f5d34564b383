"""Planar sections on several cores: chunks of heights cut in forked worker processes.

OCC Booleans hold the GIL-free C++ work but FreeCAD's Python bindings do not release the GIL,
so threads do not help; processes do. Workers are forked after the slicer is built, so they
inherit the validated solids without re-reading the file, and they send back each chunk's
section faces as BREP text, OCC's own lossless format.
"""
from __future__ import annotations

import multiprocessing
import os
from concurrent.futures import ProcessPoolExecutor
from typing import Callable, Sequence

import numpy as np

from freecad_conformal.errors import GeometryError
from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry.planar_faces import SectionFace

#: Heights per job: at least JOB_MIN, about JOBS_PER_WORKER jobs per worker.
JOB_MIN = 4
JOBS_PER_WORKER = 6

_WORKER_SLICER = None  # set in the parent just before forking; inherited by the workers


def default_workers() -> int:
    return max(1, min(os.cpu_count() or 1, 8))


def _cut_chunk_as_brep(solid_index: int, heights: np.ndarray) -> list[tuple[str, list]]:
    """Per height: the faces as one BREP text, and each face's (area, centroid)."""
    _, Part = import_freecad()
    per_height = _WORKER_SLICER.cut_chunk(solid_index, heights)
    return [(Part.makeCompound([item.face for item in items]).exportBrepToString() if items else "",
             [(item.area, item.centroid) for item in items]) for items in per_height]


def parallel_sections(slicer, heights: Sequence[float], workers: int,
                      progress: Callable[[int, int], None] | None = None) -> list:
    """Like `slicer.sections(heights)`, with chunks spread over `workers` processes."""
    global _WORKER_SLICER
    _, Part = import_freecad()
    levels = np.asarray(heights, dtype=float).reshape(-1)
    if not np.all(np.isfinite(levels)):
        raise GeometryError(f"section heights must be finite, got {levels[~np.isfinite(levels)][0]!r}")
    levels, where = np.unique(levels, return_inverse=True)
    # Face-by-face layers cost about the same each: small jobs keep both cores busy to the
    # end. Boolean fallbacks still share one Boolean per job.
    size = max(JOB_MIN, min(slicer.CHUNK, -(-len(levels) // (JOBS_PER_WORKER * workers))))
    jobs = [(solid_index, chunk) for solid_index in range(len(slicer.solids))
            for chunk in slicer._chunks(solid_index, levels, size)]
    faces_at: list[list] = [[] for _ in levels]
    _WORKER_SLICER = slicer
    try:
        context = multiprocessing.get_context("fork")
        with ProcessPoolExecutor(max_workers=workers, mp_context=context) as pool:
            futures = [pool.submit(_cut_chunk_as_brep, solid_index, levels[chunk])
                       for solid_index, chunk in jobs]
            done_layers = 0
            for (solid_index, chunk), future in zip(jobs, futures):
                for index, (text, props) in zip(chunk, future.result()):
                    if text:
                        shape = Part.Shape()
                        shape.importBrepFromString(text, False)
                        faces_at[index].extend(SectionFace(face, area, centroid)
                                               for face, (area, centroid) in zip(shape.Faces, props))
                done_layers += len(chunk)
                if progress is not None:
                    progress(min(done_layers, len(levels)), len(levels))
    finally:
        _WORKER_SLICER = None
    return [slicer._make_section(levels[k], list(faces_at[k])) for k in where]
