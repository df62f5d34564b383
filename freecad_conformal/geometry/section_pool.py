"""Planar sections of a `PlanarSlicer`, on one core or several: heights cut in this
process and in worker processes.

OCC does its work in C++, but FreeCAD's Python bindings do not release the GIL,
so threads do not help; processes do. With OCCT before 7.8 (FreeCAD 0.20) workers are forked
after the slicer is built, so they inherit the validated solids without re-reading the file.
OCCT 7.8 (FreeCAD 1.0) runs Booleans on a thread pool whose threads do not survive `fork`
(a forked worker deadlocks), so there workers come from a fork server started clean, and
each builds the slicer once from its solids in OCC's binary format. Workers send back each
job's section faces in that format, which keeps every real (geometry/occ_binary.py), and the
jobs cut here take the same trip: a section is the same whichever process cut it. This
process cuts too: it takes jobs from
the same shared counter as the workers, so N cores need N − 1 workers, and whoever is free
takes the next job.
"""
from __future__ import annotations

import multiprocessing
import os
from queue import Empty
from typing import Callable, Sequence

import numpy as np

from freecad_conformal.errors import GeometryError
from freecad_conformal.freecad_env import import_freecad, inside_freecad
from freecad_conformal.geometry.boxes import box_values, optimal_box, seed_boxes
from freecad_conformal.geometry.occ_binary import faces_from_binary, faces_to_binary, from_binary, to_binary
from freecad_conformal.geometry.loops import loops_of_faces, loops_with_wires
from freecad_conformal.geometry.planar_faces import SectionFace
from freecad_conformal.geometry.solids import checked_elsewhere

#: Heights per job: at least JOB_MIN, about JOBS_PER_WORKER jobs per worker. The last job
#: a process takes decides how long the other waits: a twelfth of a worker's share (the
#: bottle's 350 sections: 15 a job, 0.1 s each) against the binary trip each job takes.
JOB_MIN = 4
JOBS_PER_WORKER = 12

_WORKER_SLICER = None  # fork: set in the parent just before forking, inherited by workers
#: First OCCT version whose Booleans run on a thread pool that does not survive fork.
THREAD_POOL_OCC = (7, 8)


def occ_version() -> tuple[int, ...]:
    _, Part = import_freecad()
    return tuple(int(p) for p in str(Part.OCC_VERSION).split(".")[:2] if p.isdigit())


def start_method() -> str:
    """"fork" where OCC survives it (workers inherit the built slicer), else "forkserver"."""
    return "fork" if occ_version() < THREAD_POOL_OCC else "forkserver"


#: What the fork server loads once for all the workers it forks: the sections, and FreeCAD
#: itself (0.10 s of each worker's start on the bottle). A module that cannot be imported
#: there is skipped by multiprocessing; the worker then imports it as before.
FORKSERVER_PRELOAD = ["freecad_conformal.geometry.sections", "FreeCAD", "Part"]


def worker_context():
    """The multiprocessing context section workers start from (`start_method`)."""
    method = start_method()
    context = multiprocessing.get_context(method)
    if method == "forkserver":
        context.set_forkserver_preload(FORKSERVER_PRELOAD)
    return context


def warm_workers(solid, thickness: float) -> None:
    """Start the fork server now, on the other core, where sectioning `solid` in layers of
    `thickness` (mm) will want a worker (`useful_workers`): started by the first worker, it
    held this process 0.10 s, and the worker then loaded FreeCAD itself. Nothing to do
    where workers are forked (FreeCAD 0.20) or none would start."""
    if start_method() != "forkserver":
        return
    box = solid.BoundBox
    layers = max(box.XLength, box.YLength, box.ZLength) / thickness     # checked: > 0
    if useful_workers(AUTO, int(layers * faces_work(solid.Solids))) < 2:
        return
    worker_context()
    from multiprocessing import forkserver

    try:
        forkserver.ensure_running()
    except (OSError, ValueError):
        # Only a head start: where the server cannot start now, the first worker tries
        # again and reports what stops it.
        return


def slicer_spec(slicer) -> tuple:
    """What a fresh worker needs to build the same slicer: its class (pickled by name),
    solids in OCC's binary format (the very solids: a worker's sections are then this
    process's), direction, chord tolerance, the face-by-face switch, and per solid its
    faces' optimal boxes (`boxes.box_values`)."""
    return (type(slicer), [to_binary(solid) for solid in slicer.solids],
            tuple(slicer.frame.n), slicer.chord_tolerance, slicer.face_by_face,
            [[box_values(optimal_box(face)) for face in solid.Faces] for solid in slicer.solids])


def slicer_from(spec: tuple):
    """The slicer `spec` describes, built once per worker. Its solids passed OCC's check
    in the parent (`solids_of`) and their faces were boxed there: checking and boxing the
    copies again took 0.12 s of each worker's 0.28 s start on the bottle (FreeCAD 1.0)."""
    global _WORKER_SLICER
    if _WORKER_SLICER is None:
        _, Part = import_freecad()
        slicer_class, written, direction, chord, face_by_face, face_boxes = spec
        solids = [from_binary(data).Solids[0] for data in written]
        for solid, values in zip(solids, face_boxes):
            checked_elsewhere(solid)
            seed_boxes(solid.Faces, values)
        shape = solids[0] if len(solids) == 1 else Part.Compound(solids)
        _WORKER_SLICER = slicer_class(shape, direction, chord, face_by_face=face_by_face)
    return _WORKER_SLICER


def default_workers() -> int:
    return max(1, min(os.cpu_count() or 1, 8))


#: Sections × faces below which `workers=AUTO` stays in this process: a worker costs a
#: fork (FreeCAD 0.20: ~20 ms) or a fresh interpreter that reads the solids again (1.x:
#: ~1 s), and face-by-face sections cost ~10 µs per face (bottle: 900 sections of ~40
#: faces in 9 s on one core).
MIN_PARALLEL_WORK = 20_000

#: Surfaces a plane meets in closed form; the others go through OCC's surface-surface
#: intersection, which costs about this many analytic faces' sections (a modelled thread's
#: swept B-spline faces: 1,805 sections in 8.0 s, 4.4 ms each), so a few such faces make
#: a job worth the second core.
ANALYTIC_SURFACES = ("Plane", "Cylinder", "Cone", "Sphere", "Toroid")
FREEFORM_FACE_WORK = 400

#: `workers` value meaning "as many as help": every core for large jobs in a plain Python
#: main process, else 1.
AUTO = 0


def useful_workers(requested: int, work: int) -> int:
    """Processes to cut `work` (sections × faces) with when `requested` were asked for.

    AUTO stays in this process inside FreeCAD (its executable cannot start workers, and a
    GUI process should not fork), in a process that is itself a worker (batch's, whose
    pool already fills the cores) and for small jobs. A daemonic process may have no
    children at all, whatever was asked."""
    if multiprocessing.current_process().daemon:
        return 1
    if requested != AUTO:
        return max(1, requested)
    if inside_freecad() or multiprocessing.parent_process() is not None or work < MIN_PARALLEL_WORK:
        return 1
    return default_workers()


def section_work(slicer) -> int:
    """What one section of `slicer`'s solids costs, in analytic faces' sections."""
    work = getattr(slicer, "_section_work", None)
    if work is None:
        work = slicer._section_work = faces_work(slicer.solids)
    return work


def faces_work(solids) -> int:
    """What one plane through all of `solids` costs, in analytic faces' sections."""
    return sum(1 if type(face.Surface).__name__ in ANALYTIC_SURFACES else FREEFORM_FACE_WORK
               for solid in solids for face in solid.Faces)


def job_as_binary(cut: list) -> tuple[bytes, list]:
    """A job's sections (per height: SectionFaces, or None where the face-by-face cut gave
    up) as one binary compound of all their faces, with each height's [whether each face's
    first wire is its outer one] or None: one file's trip per job, not per height."""
    faces = [item.face for items in cut if items is not None for item in items]
    layout = [None if items is None else [item.outer_first for item in items] for items in cut]
    return faces_to_binary(faces), layout


def job_from_binary(data: bytes, layout: list) -> list:
    """The job's sections `job_as_binary` wrote."""
    faces = iter(faces_from_binary(data))
    return [None if flags is None else [SectionFace(next(faces), flag) for flag in flags]
            for flags in layout]


def _cut(solid_index: int, heights: np.ndarray, boolean: bool, slicer=None) -> list:
    slicer = slicer if slicer is not None else _WORKER_SLICER
    return (slicer.cut_boolean if boolean else slicer.cut_faces)(solid_index, heights)


def _worker(jobs: list, counter, results, spec: tuple | None = None,
            with_loops: bool = False) -> None:
    """Worker: takes jobs from the shared counter until none is left (`spec`: the slicer to
    build, for workers that did not inherit it; `with_loops`: send each height's loop
    points too, `loop_points`)."""
    try:
        slicer = slicer_from(spec) if spec is not None else _WORKER_SLICER
        while (index := _claim(counter)) < len(jobs):
            sent = job_as_binary(_cut(*jobs[index]))
            loops = loop_points(job_from_binary(*sent), slicer) if with_loops else None
            results.put((index, (sent, loops)))
        results.put((None, None))
    except BaseException as exc:  # noqa: BLE001 - reported to the parent, which raises it
        results.put((None, f"{type(exc).__name__}: {exc}"))


def _claim(counter) -> int:
    with counter.get_lock():
        index = counter.value
        counter.value += 1
    return index


def loop_points(cut: list, slicer) -> list:
    """Per height of a job as sent: its loops as (face index, outer, points in the layer
    frame), in the order `loops_of_faces` makes them (None where the face-by-face cut gave
    up). Made by the
    process that cut the job, from the faces as sent, so that the points are those this
    process would discretise from the same faces (the bottle's 350 sections' loops took
    0.25 s here after both cores had cut)."""
    return [None if items is None else
            [(loop.face_index, loop.outer, loop.points) for loop in loops_of_faces(
                [item.face for item in items], slicer.frame, slicer.chord_tolerance,
                outer_first=[item.outer_first for item in items])]
            for items in cut]


def _as_sent(cut: list) -> list:
    """A job's sections as a worker's come back: which process cuts a job depends on timing
    and the count of processes, and a shape read back from binary keeps every point but not
    always every last bit OCC derives from it (CrankArm's pieces integrated their volume
    differently), so the sections cut here take the same trip (0.33 ms a section on the
    bottle; BREP text took 1.6 ms)."""
    return job_from_binary(*job_as_binary(cut))


def cut_sections(slicer, heights: Sequence[float], workers: int = 1,
                 progress: Callable[[int, int], None] | None = None,
                 with_loops: bool = False) -> list:
    """`slicer`'s sections at `heights` (any order, in the order given), the work spread
    over `workers` processes (this one included; AUTO: see `useful_workers`). With
    `with_loops` (a caller that reads every section's loops) each process discretises the
    loops of the sections it cut (`loop_points`).

    First every height is cut face by face in small jobs (they cost about the same each,
    so small jobs keep both cores busy to the end); then the layers that path left go to
    Booleans of up to `CHUNK` planes each. Where several processes cut, the heights the
    face-by-face cut is expected to leave (`expected_booleans`) are cut by the Boolean
    meanwhile, first; a fallback Boolean that turns out to be one of those is not made again
    (the bottle's two heights: 0.09 s that one core spent alone after both had cut).
    """
    levels = np.asarray(heights, dtype=float).reshape(-1)
    if not np.all(np.isfinite(levels)):
        raise GeometryError(f"section heights must be finite, got {levels[~np.isfinite(levels)][0]!r}")
    levels, where = np.unique(levels, return_inverse=True)
    workers = useful_workers(workers, len(levels) * section_work(slicer))
    size = max(JOB_MIN, min(slicer.CHUNK, -(-len(levels) // (JOBS_PER_WORKER * workers))))
    jobs = [(solid_index, chunk) for solid_index in range(len(slicer.solids))
            for chunk in slicer._chunks(solid_index, levels, size)]
    if slicer.face_by_face and workers > 1:
        # Built here, the cutters (and their faces' parameter domains) are inherited by the
        # forked workers instead of being built again in each.
        for solid_index in range(len(slicer.solids)):
            slicer.cutter(solid_index).prepare()
    faces_at: list[list] = [[] for _ in levels]
    left: dict[int, list[int]] = {}

    def report(claimed: int) -> None:
        if progress is not None:
            progress(int(len(levels) * min(claimed, len(jobs)) / max(len(jobs), 1)), len(levels))

    guesses = expected_booleans(slicer, levels, jobs) if workers > 1 else []
    made = _shared(slicer, levels, guesses + jobs, [True] * len(guesses) + [False] * len(jobs),
                   workers, report, with_loops)
    guessed = {(solid_index, tuple(chunk)): result
               for (solid_index, chunk), (result, _) in zip(guesses, made)}
    known: list[list | None] = [[] for _ in levels]     # per height: its loops, if sent
    for (solid_index, chunk), (result, loops) in zip(jobs, made[len(guesses):]):
        for place, (index, faces) in enumerate(zip(chunk, result)):
            if faces is None:
                left.setdefault(solid_index, []).append(index)
                known[index] = None
                continue
            if loops is None or known[index] is None:
                known[index] = None
            else:
                known[index].append((len(faces_at[index]), loops[place]))
            faces_at[index].extend(faces)
    fallbacks = [(solid_index, np.array(indices[k:k + slicer.CHUNK]))
                 for solid_index, indices in left.items()
                 for k in range(0, len(indices), slicer.CHUNK)]
    still = [job for job in fallbacks if (job[0], tuple(job[1])) not in guessed]
    for job, (result, _) in zip(still, _shared(slicer, levels, still, [True] * len(still),
                                               workers)):
        guessed[(job[0], tuple(job[1]))] = result
    for solid_index, chunk in fallbacks:
        for index, faces in zip(chunk, guessed[(solid_index, tuple(chunk))]):
            faces_at[index].extend(faces)
    boolean = sum(len(indices) for indices in left.values())
    slicer.counts["boolean"] += boolean
    slicer.counts["face_by_face"] += sum(len(chunk) for _, chunk in jobs) - boolean
    loops = [None if not parts else loops_with_wires(
        [item.face for item in faces_at[k]],
        [(first + face, outer, points) for first, made in parts for face, outer, points in made])
        for k, parts in enumerate(known)]
    return [slicer.make_section(levels[k], list(faces_at[k]), loops[k]) for k in where]


def expected_booleans(slicer, levels: np.ndarray, jobs: list) -> list:
    """The fallback Booleans the face-by-face `jobs` are expected to leave, as `cut_sections`
    would group them (per solid, `CHUNK` heights each): heights whose plane touches one of
    the solid's circular edges at its extreme (`FaceCutter.touches_circle`). Vertices need
    no guess: layer heights are moved off them (`PlanarSlicer.off_vertices`)."""
    if not slicer.face_by_face:
        return []
    guesses = []
    for solid_index in range(len(slicer.solids)):
        cutter = slicer.cutter(solid_index)
        indices = [int(index) for job_solid, chunk in jobs if job_solid == solid_index
                   for index in chunk if cutter.touches_circle(float(levels[index]))]
        guesses.extend((solid_index, np.array(indices[k:k + slicer.CHUNK]))
                       for k in range(0, len(indices), slicer.CHUNK))
    return guesses


#: Seconds between checks that the workers are still alive while waiting for their results.
WORKER_POLL = 0.5


def _sent_already(queue) -> tuple | None:
    """The next (index, payload) a worker put on `queue`, None when there is none yet.
    Raises GeometryError when a worker reported a failure."""
    try:
        return _unless_failed(*queue.get_nowait())
    except Empty:
        return None


def next_result(queue, processes: list) -> tuple:
    """The next (index, payload) a worker put on `queue`; (None, None) when one finished.
    Raises GeometryError when a worker reported a failure or all died without a word."""
    while True:
        try:
            return _unless_failed(*queue.get(timeout=WORKER_POLL))
        except Empty:
            if not any(process.is_alive() for process in processes):
                raise GeometryError("a section worker process died before it finished") from None


def _unless_failed(index, payload) -> tuple:
    """A worker's (index, payload); GeometryError for its report of a failure."""
    if index is None and payload is not None:
        raise GeometryError(f"a section worker failed: {payload}")
    return index, payload


def _shared(slicer, levels: np.ndarray, jobs: list, boolean: list[bool], workers: int,
            report: Callable[[int], None] | None = None, with_loops: bool = False) -> list:
    """Each job's (per-height results, per-height loop points or None), cut by this process
    and `workers - 1` forked ones (`boolean`: per job, whether the Boolean cuts it);
    loop points only where `with_loops` and several processes cut (one process discretises
    its loops when they are read, as it always did). A job's faces take the binary trip
    whenever another process could have cut it: unless it is the only face-by-face job, the
    same whatever the count of processes."""
    global _WORKER_SLICER
    if not jobs:
        return []
    work = [(solid_index, levels[chunk], flag) for (solid_index, chunk), flag in zip(jobs, boolean)]
    if workers == 1 or len(jobs) == 1:
        results = []
        for done, job in enumerate(work, start=1):
            results.append((_as_sent(_cut(*job, slicer)) if len(jobs) > 1 or job[2]
                            else _cut(*job, slicer), None))
            if report is not None:
                report(done)
        return results
    results: list = [None] * len(jobs)
    context = worker_context()
    counter = context.Value("i", 0)
    queue = context.Queue()
    spec = None
    if context.get_start_method() == "fork":
        _WORKER_SLICER = slicer
    else:
        spec = slicer_spec(slicer)
    processes = []
    try:
        for _ in range(min(workers, len(jobs)) - 1):
            process = context.Process(target=_worker, daemon=True,
                                      args=(work, counter, queue, spec, with_loops))
            process.start()
            processes.append(process)
        running = len(processes)

        def take(index, payload) -> None:
            nonlocal running
            if index is None:
                running -= 1
            else:
                sent, loops = payload
                results[index] = (job_from_binary(*sent), loops)

        while (index := _claim(counter)) < len(jobs):
            sent = _as_sent(_cut(*work[index], slicer))
            results[index] = (sent, loop_points(sent, slicer) if with_loops else None)
            if report is not None:
                report(index + 1)
            # Read the workers' jobs as they come: read at the end, they kept this process
            # busy while the others had nothing left to cut (the bottle: 12 jobs, 0.05 s).
            while (item := _sent_already(queue)) is not None:
                take(*item)
        while running:
            take(*next_result(queue, processes))
    finally:
        _WORKER_SLICER = None
        for process in processes:
            if process.is_alive():
                process.terminate()
            process.join()
    if report is not None:
        report(len(jobs))
    return results
