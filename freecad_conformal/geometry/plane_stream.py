"""Sections by planes of any normal, cut on a second core while the caller goes on.

3-D layers (`layers/tilted.py`) find each plane from the one below: a probe section a layer
ahead, then the plane's own. The probe's plane is known as soon as the plane below is
chosen, before that plane is cut, so it is asked `ahead` and cut on the worker while the
chain cuts the plane below here; the chain then reads it (`probe`). Each layer's region is
cut on the plane halfway between its two, which nothing later reads (the fan's hub: 284 of
872 sections): this process cuts those while it waits for a probe, and the rest are shared
between both at the end (`results`). Where the chain cut two planes a layer here, it now
cuts one (the fan's 3-D layers: 556 cuts here and 248 on the worker before).

The worker is forked where OCC survives it, else started from a fork server with the
solids in OCC's binary format (`section_pool.start_method`); inside FreeCAD, in a daemonic
process or for small stacks every plane is cut here when it is read. The worker's sections
come back in that format, which keeps every real (geometry/occ_binary.py), and probes and
middle planes cut here take the same trip, so the layers (and the G-code) do not depend on
where they were cut; their area and centroid travel with them (not integrated again).
"""
from __future__ import annotations

import multiprocessing
import time
from queue import Empty

import numpy as np

from freecad_conformal.geometry import section_pool
from freecad_conformal.geometry.frames import LayerFrame
from freecad_conformal.geometry.occ_binary import faces_from_binary, faces_to_binary
from freecad_conformal.geometry.sections import PlanarSection, PlanarSlicer

#: Weight of the newest measure in the running averages of a probe's turnaround and of a
#: middle plane's cut, which decide whether a middle plane fits in a wait.
AVERAGE_WEIGHT = 0.2

#: Job kinds on the worker's queue: a probe the chain waits for; the middle planes left at
#: the end, taken one by one from a counter shared with this process.
PROBE, SHARE = "probe", "share"


def _section(slicer: PlanarSlicer, point: np.ndarray, normal: np.ndarray) -> tuple:
    """One plane's section as (height, its faces, area, centroid): what
    `PlaneStream` rebuilds it from, wherever it was cut."""
    turned = slicer.turned(normal)
    height = float(point @ turned.frame.n)
    section = turned.section(height)
    return height, section.faces, section.area, section.centroid


def _as_sent(cut: tuple) -> tuple:
    """A section cut here as a worker's comes back (through the binary format)."""
    height, faces, area, centroid = cut
    return height, faces_from_binary(faces_to_binary(faces)), area, centroid


def _worker(jobs, results, counter, source) -> None:
    """Cuts planes from `jobs` until None comes: a probe, or the list of middle planes
    left, claimed from `counter` with the parent. `source`: the slicer (forked: inherited,
    not pickled) or its spec (`section_pool.slicer_spec`) to build it from."""
    try:
        slicer = source if isinstance(source, PlanarSlicer) else section_pool.slicer_from(source)
        while (job := jobs.get()) is not None:
            kind, key, point, normal = job
            if kind == PROBE:
                cuts = [(key, (point, normal))]
            else:
                cuts = _claimed(counter, key)
            for found, plane in cuts:
                height, faces, area, centroid = _section(slicer, *plane)
                results.put(((kind, found), (height, faces_to_binary(faces), area, centroid)))
        results.put((None, None))
    except BaseException as exc:  # noqa: BLE001 - reported to the parent, which raises it
        results.put((None, f"{type(exc).__name__}: {exc}"))


def _claimed(counter, planes: list):
    """(index, plane) of the planes this process claims from `counter`, one at a time."""
    while (claimed := section_pool.claim(counter)) < len(planes):
        index, point, normal = planes[claimed]
        yield index, (point, normal)


def _averaged(average: float | None, value: float) -> float:
    return value if average is None else average + AVERAGE_WEIGHT * (value - average)


def _key(point: np.ndarray, normal: np.ndarray) -> bytes:
    return np.asarray(point, dtype=float).tobytes() + np.asarray(normal, dtype=float).tobytes()


class PlaneStream:
    """Planes (point, normal): middle planes `submit`ted one by one, their sections returned
    in order by `results()`; probes asked `ahead` and read with `probe`. `expected` planes
    decide whether a worker pays (`useful_workers`)."""

    def __init__(self, slicer: PlanarSlicer, expected: int, workers: int = section_pool.AUTO):
        self._slicer = slicer
        self._planes: list[tuple[np.ndarray, np.ndarray]] = []
        #: middle planes cut here (index -> cut as sent), and how many were looked at
        self._cut: dict[int, tuple] = {}
        self._filled = 0
        #: probes asked ahead and not read yet (key -> its cut once it came back), and when
        #: each was asked
        self._ahead: dict[bytes, tuple | None] = {}
        self._asked: dict[bytes, float] = {}
        #: running averages (s): from asking a probe to its answer; cutting a middle plane
        self._turnaround: float | None = None
        self._fill_time: float | None = None
        self._process = None
        work = expected * section_pool.section_work(slicer)
        if section_pool.useful_workers(workers, work) < 2:
            return
        method = section_pool.start_method()
        context = multiprocessing.get_context(method)
        self._jobs, self._results = context.Queue(), context.Queue()
        self._counter = context.Value("i", 0)
        source = slicer
        if method != "fork":
            source = section_pool.slicer_spec(slicer)
            context.set_forkserver_preload(["freecad_conformal.geometry.sections"])
        self._process = context.Process(target=_worker, daemon=True,
                                        args=(self._jobs, self._results, self._counter, source))
        self._process.start()

    def submit(self, point: np.ndarray, normal: np.ndarray) -> None:
        """A middle plane, cut whenever a process is free (`results` returns it)."""
        self._planes.append((np.asarray(point, dtype=float), np.asarray(normal, dtype=float)))

    def ahead(self, point: np.ndarray, normal: np.ndarray) -> None:
        """A probe the chain will read next (if the plane below it stands): cut on the
        worker meanwhile (here, when it is read, without one)."""
        if self._process is None:
            return
        key = _key(point, normal)
        if key not in self._ahead:
            self._ahead[key] = None
            self._asked[key] = time.perf_counter()
            self._jobs.put((PROBE, key, np.asarray(point, dtype=float),
                            np.asarray(normal, dtype=float)))

    def probe(self, point: np.ndarray, normal: np.ndarray) -> PlanarSection:
        """The section of the plane (point, normal): the worker's if it was asked ahead,
        else cut here. While the worker cuts it, this process cuts a middle plane when one
        fits in the wait (`_fits`): one cut here past the probe's answer keeps the worker
        idle and the chain waiting (filling every wait made the fan's chain cut two planes
        a layer here again)."""
        key = _key(point, normal)
        if self._process is None or key not in self._ahead:
            return self._rebuilt(normal, _as_sent(_section(self._slicer, point, normal)))
        while self._ahead[key] is None:
            self._take(wait=False)
            if self._ahead[key] is not None:
                break
            if self._filled < len(self._planes) and self._fits(key):
                start = time.perf_counter()
                self._fill()
                self._fill_time = _averaged(self._fill_time, time.perf_counter() - start)
                continue
            self._take(wait=True)
            if self._ahead[key] is not None:
                # Answered while this process waited: the turnaround is measured.
                self._turnaround = _averaged(self._turnaround,
                                             time.perf_counter() - self._asked[key])
        cut = self._ahead.pop(key)
        self._asked.pop(key, None)
        # Probes asked for planes the chain left (a plane below it did not stand) are
        # not waited for: their answers are dropped as they come.
        return self._rebuilt(normal, cut)

    def _fits(self, key: bytes) -> bool:
        """Whether a middle plane is expected to be cut before the probe `key` comes back
        (unknown at first: the first waits are waited, which measures the turnaround)."""
        if self._turnaround is None:
            return False
        left = self._turnaround - (time.perf_counter() - self._asked[key])
        return left > (self._fill_time if self._fill_time is not None else self._turnaround)

    def _take(self, wait: bool) -> None:
        """Read one answer of the worker into place (waiting for it if `wait`)."""
        try:
            if wait:
                kind_key, payload = section_pool.next_result(self._results, [self._process])
            else:
                kind_key, payload = self._results.get_nowait()
        except Empty:
            return
        if kind_key is None:
            if payload is not None:
                from freecad_conformal.errors import GeometryError

                raise GeometryError(f"a section worker failed: {payload}")
            return
        _, key = kind_key          # only probes are answered before `results`
        if key in self._ahead:
            height, data, area, centroid = payload
            self._ahead[key] = (height, faces_from_binary(data), area, centroid)

    def _fill(self) -> None:
        """Cut the next middle plane not cut yet, here."""
        index = self._filled
        self._filled += 1
        if index not in self._cut:
            self._cut[index] = _as_sent(_section(self._slicer, *self._planes[index]))

    def results(self) -> list[PlanarSection]:
        """Every submitted plane's section, in order (the worker, if any, then stops)."""
        left = range(self._filled, len(self._planes))
        if self._process is None:
            # Through the binary format as the worker's come back: inside FreeCAD the
            # planes are cut here, on the command line by both processes.
            for index in left:
                self._cut[index] = _as_sent(_section(self._slicer, *self._planes[index]))
        else:
            try:
                self._share(list(left))
            finally:
                self.close()
        return [self._rebuilt(normal, self._cut[index])
                for index, (_, normal) in enumerate(self._planes)]

    def _share(self, left: list[int]) -> None:
        """The middle planes not cut yet, claimed one by one by the worker and this process."""
        planes = [(index, *self._planes[index]) for index in left]
        self._jobs.put((SHARE, planes, None, None))
        self._jobs.put(None)
        for index, plane in _claimed(self._counter, planes):
            self._cut[index] = _as_sent(_section(self._slicer, *plane))
        while (result := section_pool.next_result(self._results, [self._process]))[0] is not None:
            (kind, key), (height, data, area, centroid) = result
            if kind == SHARE:
                self._cut[key] = (height, faces_from_binary(data), area, centroid)

    def _rebuilt(self, normal: np.ndarray, cut: tuple) -> PlanarSection:
        height, faces, area, centroid = cut
        return PlanarSection(height=height, frame=LayerFrame.for_direction(normal),
                             faces=list(faces), area=area, centroid=centroid,
                             chord_tolerance=self._slicer.chord_tolerance)

    def close(self) -> None:
        """Stop the worker (idempotent)."""
        if self._process is not None:
            if self._process.is_alive():
                self._process.terminate()
            self._process.join()
            self._process = None
