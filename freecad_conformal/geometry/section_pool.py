"""Planar sections on several cores: heights cut in forked worker processes.

OCC does its work in C++, but FreeCAD's Python bindings do not release the GIL,
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


def _as_brep(items: list | None):
    """Faces as one BREP text with each face's (area, centroid); None stays None."""
    if items is None:
        return None
    _, Part = import_freecad()
    text = Part.makeCompound([item.face for item in items]).exportBrepToString() if items else ""
    return text, [(item.area, item.centroid) for item in items]


def _cut_in_worker(solid_index: int, heights: np.ndarray, boolean: bool) -> list:
    cut = _WORKER_SLICER.cut_boolean if boolean else _WORKER_SLICER.cut_faces
    return [_as_brep(items) for items in cut(solid_index, heights)]


def _from_brep(text: str, props: list) -> list[SectionFace]:
    if not text:
        return []
    _, Part = import_freecad()
    shape = Part.Shape()
    shape.importBrepFromString(text, False)
    return [SectionFace(face, area, centroid) for face, (area, centroid) in zip(shape.Faces, props)]


def parallel_sections(slicer, heights: Sequence[float], workers: int,
                      progress: Callable[[int, int], None] | None = None) -> list:
    """Like `slicer.sections(heights)`, with the work spread over `workers` processes.

    First every height is cut face by face in small jobs (they cost about the same each,
    so small jobs keep both cores busy to the end); then the layers that path left go to
    Booleans of up to `CHUNK` planes each.
    """
    global _WORKER_SLICER
    levels = np.asarray(heights, dtype=float).reshape(-1)
    if not np.all(np.isfinite(levels)):
        raise GeometryError(f"section heights must be finite, got {levels[~np.isfinite(levels)][0]!r}")
    levels, where = np.unique(levels, return_inverse=True)
    size = max(JOB_MIN, min(slicer.CHUNK, -(-len(levels) // (JOBS_PER_WORKER * workers))))
    jobs = [(solid_index, chunk) for solid_index in range(len(slicer.solids))
            for chunk in slicer._chunks(solid_index, levels, size)]
    faces_at: list[list] = [[] for _ in levels]
    if slicer.face_by_face:
        # Built here, the cutters (and their faces' parameter domains) are inherited by the
        # forked workers instead of being built again in each.
        for solid_index in range(len(slicer.solids)):
            slicer.cutter(solid_index).prepare()
    _WORKER_SLICER = slicer
    left: dict[int, list[int]] = {}
    try:
        context = multiprocessing.get_context("fork")
        with ProcessPoolExecutor(max_workers=workers, mp_context=context) as pool:
            futures = [pool.submit(_cut_in_worker, solid_index, levels[chunk], False)
                       for solid_index, chunk in jobs]
            for done, ((solid_index, chunk), future) in enumerate(zip(jobs, futures), start=1):
                for index, result in zip(chunk, future.result()):
                    if result is None:
                        left.setdefault(solid_index, []).append(index)
                    else:
                        faces_at[index].extend(_from_brep(*result))
                if progress is not None:
                    progress(int(len(levels) * done / len(jobs)), len(levels))
            fallbacks = [(solid_index, np.array(indices[k:k + slicer.CHUNK]))
                         for solid_index, indices in left.items()
                         for k in range(0, len(indices), slicer.CHUNK)]
            futures = [pool.submit(_cut_in_worker, solid_index, levels[chunk], True)
                       for solid_index, chunk in fallbacks]
            for (solid_index, chunk), future in zip(fallbacks, futures):
                for index, result in zip(chunk, future.result()):
                    faces_at[index].extend(_from_brep(*result))
    finally:
        _WORKER_SLICER = None
    boolean = sum(len(indices) for indices in left.values())
    slicer.counts["boolean"] += boolean
    slicer.counts["face_by_face"] += sum(len(chunk) for _, chunk in jobs) - boolean
    return [slicer._make_section(levels[k], list(faces_at[k])) for k in where]
