"""Runners: a worker that dies, a task that raises, Dask on a LocalCluster, Dask missing."""
from __future__ import annotations

import csv
import os
import signal
import sys
import threading
import time
from dataclasses import replace
from pathlib import Path

import pytest

from freecad_conformal.jobs.batch import runners
from freecad_conformal.jobs.batch.report import new_row
from freecad_conformal.jobs.batch.run import run_batch
from freecad_conformal.errors import ConformalError
from freecad_conformal.jobs.plan import PlanOptions
from tests.geometry.batch_parts import EXPECTED_LAYERS, make_parts

#: Exit status of the simulated crash (a segfault in OCC would end the worker the same way).
CRASH_STATUS = 70


def crash_on_cylinder(job, options):
    """A stand-in task (module level, so spawned workers can import it): the cylinder kills
    its worker process, the box raises, every other part "plans" instantly."""
    if job.part == "cyl.brep":
        os._exit(CRASH_STATUS)
    if job.part == "box.step":
        raise RuntimeError("simulated bug")
    row = new_row(job.part, job.path, job.body_label)
    row.update(status="ok", subparts=1, layers=1, material_mm3=1.0, time_s=1.0)
    return {"row": row, "gcode": f"(part {job.part})\n"}


@pytest.fixture(scope="module")
def parts(tmp_path_factory):
    return make_parts(tmp_path_factory.mktemp("batch-runners"))


@pytest.mark.slow
def test_a_dying_worker_fails_only_its_part(parts, tmp_path):
    inputs = [str(parts[name]) for name in ("cyl", "box", "two")]
    result = run_batch(inputs, PlanOptions(), tmp_path, workers=2, task=crash_on_cylinder)
    by_part = {row["part"]: row for row in result.rows}
    assert [row["part"] for row in result.rows] == ["cyl.brep", "box.step", "two.FCStd#Left",
                                                    "two.FCStd#Right"]
    assert by_part["cyl.brep"]["error"] == runners.CRASHED
    assert by_part["box.step"]["error"] == "task error (RuntimeError): simulated bug"
    for name in ("two.FCStd#Left", "two.FCStd#Right"):
        assert by_part[name]["status"] == "ok"
    assert (tmp_path / "two_Left.gcode").read_text() == "(part two.FCStd#Left)\n"
    assert not (tmp_path / "cyl.gcode").exists() and not (tmp_path / "box.gcode").exists()
    assert result.failed == 2


def test_start_method_is_checked(parts, tmp_path):
    with pytest.raises(ConformalError, match="start method 'thread' is not one of spawn, fork"):
        run_batch([str(parts["box"])], PlanOptions(), tmp_path, workers=1, start_method="thread")


def test_default_start_method_forks_only_inside_freecad_before_occt_7_8(monkeypatch, App):
    from freecad_conformal.geometry.section_pool import THREAD_POOL_OCC, occ_version

    monkeypatch.setattr(sys, "executable", "/usr/bin/python3.11")
    assert runners.default_start_method() == "spawn"
    monkeypatch.setattr(sys, "executable", "/usr/bin/freecadcmd")
    # OCCT 7.8 (FreeCAD 1.x) runs Booleans on threads a forked child does not get
    expected = "fork" if occ_version() < THREAD_POOL_OCC else "spawn"
    assert runners.default_start_method() == expected


def test_missing_dask_says_how_to_install_it(monkeypatch, parts, tmp_path):
    monkeypatch.setitem(sys.modules, "distributed", None)  # makes `import distributed` fail
    with pytest.raises(ConformalError, match=r'--dask needs .* pip install "dask\[distributed\]"'):
        run_batch([str(parts["box"])], PlanOptions(), tmp_path, dask="tcp://127.0.0.1:8786")
    assert not (tmp_path / "batch-report.csv").exists()


@pytest.mark.slow
def test_dask_local_cluster_runs_the_same_jobs(parts, tmp_path):
    """Two worker processes of a LocalCluster, the same rows as a local run."""
    distributed = pytest.importorskip("distributed")
    from freecad_conformal.cli import main

    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        out = tmp_path / "out"
        inputs = [str(parts[name]) for name in ("box", "two", "broken")]
        code = main(["batch", *inputs, "--layer", "1", "--bead-width", "1", "-o", str(out),
                     "--dask", cluster.scheduler_address])
    assert code == 1
    with open(out / "batch-report.csv", newline="", encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    assert [row["part"] for row in rows] == ["box.step", "two.FCStd#Left", "two.FCStd#Right",
                                             "broken.step"]
    for row in rows[:3]:
        assert row["status"] == "ok"
        assert int(row["layers"]) == EXPECTED_LAYERS[row["part"]]
        assert (out / row["gcode"]).stat().st_size == int(row["gcode_bytes"]) > 0
    assert rows[3]["error"].startswith("cannot read broken.step")


def test_jobs_with_data_never_read_their_path(parts, tmp_path):
    """What a remote Dask worker does: the part comes as bytes, its path does not exist there."""
    from freecad_conformal.jobs.batch.jobs import expand_inputs
    from freecad_conformal.jobs.batch.worker import load_part

    for job in expand_inputs([str(parts["box"]), str(parts["two"])]).jobs:
        remote = replace(job.with_data(), path=str(tmp_path / "elsewhere" / Path(job.path).name))
        assert not os.path.exists(remote.path)
        assert load_part(remote).Volume == pytest.approx(load_part(job).Volume, rel=1e-12)


#: Environment variable naming the file the stalling part creates once it has started.
STARTED = "CONFORMAL_TEST_STALL_STARTED"


def stall_on_cylinder(job, options):
    """A stand-in task: the cylinder stalls (as FreeCAD's reader does on some corrupt files),
    every other part "plans" instantly."""
    if job.part == "cyl.brep":
        Path(os.environ[STARTED]).write_text("started")
        time.sleep(120)
    row = new_row(job.part, job.path, job.body_label)
    row.update(status="ok", subparts=1, layers=1, material_mm3=1.0, time_s=1.0)
    return {"row": row, "gcode": f"(part {job.part})\n"}


@pytest.mark.slow
def test_a_part_past_the_time_limit_is_stopped_and_the_others_finish(parts, tmp_path,
                                                                     monkeypatch):
    monkeypatch.setenv(STARTED, str(tmp_path / "started"))
    inputs = [str(parts[name]) for name in ("cyl", "box", "two")]
    began = time.monotonic()
    result = run_batch(inputs, PlanOptions(), tmp_path / "out", workers=2,
                       task=stall_on_cylinder, time_limit=4.0)
    assert time.monotonic() - began < 60          # not the 120 s the part would take
    by_part = {row["part"]: row for row in result.rows}
    assert by_part["cyl.brep"]["status"] == "failed"
    assert by_part["cyl.brep"]["error"] == "stopped after the per-part time limit of 4 s"
    assert [by_part[n]["status"] for n in ("box.step", "two.FCStd#Left", "two.FCStd#Right")] \
        == ["ok"] * 3


@pytest.fixture()
def ctrl_c_raises():
    """SIGINT raising KeyboardInterrupt, as at a terminal, however the tests were started: a
    shell ignores SIGINT in the jobs it starts in the background (`cmd &`), and Python
    then leaves it ignored."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


@pytest.mark.slow
def test_ctrl_c_writes_the_report_of_the_parts_finished(parts, tmp_path, monkeypatch,
                                                        ctrl_c_raises):
    marker = tmp_path / "started"
    monkeypatch.setenv(STARTED, str(marker))
    inputs = [str(parts[name]) for name in ("box", "two", "cyl")]      # the stall comes last

    def interrupt_once_the_stall_runs():
        end = time.monotonic() + 90
        while not marker.exists() and time.monotonic() < end:
            time.sleep(0.1)
        os.kill(os.getpid(), signal.SIGINT)

    threading.Thread(target=interrupt_once_the_stall_runs, daemon=True).start()
    began = time.monotonic()
    with pytest.raises(KeyboardInterrupt, match="report of the parts so far"):
        run_batch(inputs, PlanOptions(), tmp_path / "out", workers=1, task=stall_on_cylinder)
    assert marker.exists() and time.monotonic() - began < 60
    with open(tmp_path / "out" / "batch-report.csv", newline="") as handle:
        rows = {row["part"]: row for row in csv.DictReader(handle)}
    assert [rows[n]["status"] for n in ("box.step", "two.FCStd#Left", "two.FCStd#Right")] \
        == ["ok"] * 3
    assert rows["cyl.brep"]["status"] == "failed"
    assert "interrupted (Ctrl-C)" in rows["cyl.brep"]["error"]
