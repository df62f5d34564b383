"""What a section worker builds its slicer from, and when the fork server starts early."""
from __future__ import annotations

import pytest

from freecad_conformal.geometry import section_pool
from freecad_conformal.geometry.boxes import _BOXES
from freecad_conformal.geometry.sections import PlanarSlicer
from freecad_conformal.geometry.solids import _CHECKED


@pytest.fixture
def fresh_worker(monkeypatch):
    """This process as a worker that has built no slicer yet."""
    monkeypatch.setattr(section_pool, "_WORKER_SLICER", None)


def test_worker_slicer_keeps_the_parents_check_and_boxes(App, Part, monkeypatch,
                                                        fresh_worker):
    """A worker's copy of the solids is known checked and its faces boxed as the parent
    boxed them: building its slicer neither checks nor boxes them again."""
    part = Part.makeCylinder(4, 10).fuse(Part.makeBox(12, 12, 2, App.Vector(-6, -6, 0)))
    parent = PlanarSlicer(part, (0.2, 0.1, 1.0))
    computed: list[str] = []
    building = [False]

    def recorded(cache, name: str) -> None:
        real = cache.get

        def get(shapes, compute):
            def counted():
                if building[0]:
                    computed.append(name)
                return compute()
            return real(shapes, counted)
        monkeypatch.setattr(cache, "get", get)

    recorded(_BOXES, "box")
    recorded(_CHECKED, "check")

    class Watched(PlanarSlicer):
        def __init__(self, *args, **kwargs) -> None:
            building[0] = True
            super().__init__(*args, **kwargs)
            building[0] = False

    spec = (Watched,) + section_pool.slicer_spec(parent)[1:]
    built = section_pool.slicer_from(spec)
    assert computed == []
    solid = built.solids[0]
    assert len(built.solids) == 1 and not solid.isSame(parent.solids[0])
    for face, original in zip(solid.Faces, parent.solids[0].Faces):
        box, expected = _BOXES.peek((face,)), original.optimalBoundingBox(False)
        assert (box.XMin, box.YMin, box.ZMin, box.XMax, box.YMax, box.ZMax) == (
            expected.XMin, expected.YMin, expected.ZMin, expected.XMax, expected.YMax,
            expected.ZMax)
    assert built.section(1.0).area == pytest.approx(parent.section(1.0).area, rel=1e-12)


def _ribbed(App, Part):
    """A 200 mm cylinder with a dozen ribs through it: enough faces for workers."""
    ribbed = Part.makeCylinder(20, 200)
    for k in range(12):
        ribbed = ribbed.fuse(Part.makeBox(50, 2, 200, App.Vector(-25, -1 + 0.1 * k, 0)))
    return ribbed


@pytest.fixture
def started(monkeypatch) -> list:
    """Calls to the fork server's start, recorded instead of made."""
    from multiprocessing import forkserver

    calls: list = []
    monkeypatch.setattr(forkserver, "ensure_running", lambda: calls.append(True))
    # Workers allowed here whatever the process (pytest's), for enough work.
    monkeypatch.setattr(section_pool, "useful_workers", lambda requested, work:
                        2 if work >= section_pool.MIN_PARALLEL_WORK else 1)
    return calls


def test_fork_server_starts_early_for_a_part_workers_will_cut(App, Part, monkeypatch, started):
    monkeypatch.setattr(section_pool, "start_method", lambda: "forkserver")
    tall = Part.makeCylinder(20, 200)           # 3 faces x 1,000 layers of 0.2 mm
    section_pool.warm_workers(tall, 0.2)
    assert started == []
    ribbed = _ribbed(App, Part)
    assert len(ribbed.Faces) * 1000 >= section_pool.MIN_PARALLEL_WORK
    section_pool.warm_workers(ribbed, 0.2)
    assert started == [True]


def test_fork_server_not_started_where_workers_are_forked(App, Part, monkeypatch, started):
    monkeypatch.setattr(section_pool, "start_method", lambda: "fork")
    many = Part.makeBox(10, 10, 400)
    for k in range(30):
        many = many.fuse(Part.makeCylinder(0.5, 400, App.Vector(1 + 0.25 * k, 5, 0)))
    section_pool.warm_workers(many, 0.2)
    assert started == []


def test_a_fork_server_that_cannot_start_early_does_not_stop_the_plan(App, Part, monkeypatch):
    from multiprocessing import forkserver

    def refuse():
        raise OSError("no room for a socket")

    monkeypatch.setattr(forkserver, "ensure_running", refuse)
    monkeypatch.setattr(section_pool, "useful_workers", lambda requested, work: 2)
    monkeypatch.setattr(section_pool, "start_method", lambda: "forkserver")
    section_pool.warm_workers(_ribbed(App, Part), 0.2)        # no error
