"""Sections by planes of any normal, cut on a second core while the caller goes on.

3-D layers (`layers/tilted.py`) find each plane from the one below (a probe section, then
the plane's own), a chain no second core can share; but each layer's region is cut on the
plane halfway between its two, which nothing later reads: a third of the stack's sections
(the fan's hub: 284 of 872, 4 of its 13 s). Those go to one worker process as the chain
finds them, and come back at the end.

The worker is forked where OCC survives it, else started from a fork server with the
solids in OCC's binary format (`section_pool.start_method`); inside FreeCAD, in a daemonic
process or for small stacks the planes are cut here, at the end. The worker's sections come
back in that format, which keeps every real (geometry/occ_binary.py), and those cut here take
the same trip, so the regions (and the G-code) do not depend on where they were cut; their
area and centroid, which the layers do not read, are integrated where read.
"""
from __future__ import annotations

import numpy as np

from freecad_conformal.geometry import section_pool
from freecad_conformal.geometry.frames import LayerFrame
from freecad_conformal.geometry.occ_binary import faces_from_binary, faces_to_binary
from freecad_conformal.geometry.sections import PlanarSection, PlanarSlicer


def _section(slicer: PlanarSlicer, point: np.ndarray, normal: np.ndarray) -> tuple:
    """One plane's section as (height, its faces): what `PlaneStream.results` rebuilds it
    from, wherever it was cut (its area and centroid are integrated where read)."""
    turned = slicer.turned(normal)
    height = float(point @ turned.frame.n)
    return height, turned.section(height).faces


def _worker(jobs, results, source) -> None:
    """Cuts planes from `jobs` until None comes. `source`: the slicer (forked: inherited,
    not pickled) or its spec (`section_pool.slicer_spec`) to build it from."""
    try:
        slicer = source if isinstance(source, PlanarSlicer) else section_pool.slicer_from(source)
        while (job := jobs.get()) is not None:
            index, point, normal = job
            height, faces = _section(slicer, point, normal)
            results.put((index, (height, faces_to_binary(faces))))
        results.put((None, None))
    except BaseException as exc:  # noqa: BLE001 - reported to the parent, which raises it
        results.put((None, f"{type(exc).__name__}: {exc}"))


class PlaneStream:
    """Planes (point, normal) submitted one by one, their sections returned in order by
    `results()`. `expected` planes decide whether a worker pays (`useful_workers`)."""

    def __init__(self, slicer: PlanarSlicer, expected: int, workers: int = section_pool.AUTO):
        self._slicer = slicer
        self._planes: list[tuple[np.ndarray, np.ndarray]] = []
        self._process = None
        work = expected * section_pool.section_work(slicer)
        if section_pool.useful_workers(workers, work) < 2:
            return
        context = section_pool.worker_context()
        self._jobs, self._results = context.Queue(), context.Queue()
        source = slicer
        if context.get_start_method() != "fork":
            source = section_pool.slicer_spec(slicer)
        self._process = context.Process(target=_worker, args=(self._jobs, self._results, source),
                                        daemon=True)
        self._process.start()

    def submit(self, point: np.ndarray, normal: np.ndarray) -> None:
        plane = (np.asarray(point, dtype=float), np.asarray(normal, dtype=float))
        if self._process is not None:
            self._jobs.put((len(self._planes), *plane))
        self._planes.append(plane)

    def results(self) -> list[PlanarSection]:
        """Every submitted plane's section, in order (the worker, if any, then stops)."""
        if self._process is None:
            # Through the binary format as the worker's come back (section_pool._as_sent):
            # inside FreeCAD the planes are cut here, on the command line in the worker.
            cut = [(height, faces_from_binary(faces_to_binary(faces)))
                   for height, faces in (_section(self._slicer, *plane) for plane in self._planes)]
        else:
            self._jobs.put(None)
            cut = [(height, faces_from_binary(data)) for height, data in self._collect()]
        return [PlanarSection(height=height, frame=LayerFrame.for_direction(normal),
                              faces=list(faces), chord_tolerance=self._slicer.chord_tolerance)
                for (_, normal), (height, faces) in zip(self._planes, cut)]

    def _collect(self) -> list:
        found: dict[int, tuple] = {}
        try:
            while (result := section_pool.next_result(self._results, [self._process]))[0] \
                    is not None:
                found[result[0]] = result[1]
        finally:
            self.close()
        return [found[k] for k in range(len(self._planes))]

    def close(self) -> None:
        """Stop the worker (idempotent)."""
        if self._process is not None:
            if self._process.is_alive():
                self._process.terminate()
            self._process.join()
            self._process = None
