"""The worker process the GUI runs long computations in (gui/worker.py, objects/work.py),
without the GUI: the same results as in-process, errors as one line, Cancel ends it."""
from __future__ import annotations

import time

import pytest

from freecad_conformal.gui.worker import WorkerProcess, worker_environment
from freecad_conformal.objects.work import compute, parse_progress, print_progress

pytestmark = pytest.mark.parts


@pytest.fixture(scope="module")
def pump_brep(parts_dir) -> str:
    from freecad_conformal.freecad_env import import_freecad

    _, Part = import_freecad()
    shape = Part.Shape()
    shape.read(str(parts_dir / "Pump_Nut.brep"))
    return shape.exportBrepToString()


def sections_inputs(brep: str) -> dict:
    return {"brep": brep, "mode": "planar", "chord_tolerance": 0.01,
            "direction": (0.0, 0.0, 1.0), "layer": 2.0}


def test_progress_lines_round_trip(capsys):
    print_progress(0.25, "layers of sub-part 1/4")
    print_progress(None, "posting")
    lines = capsys.readouterr().out.splitlines()
    assert parse_progress(lines[0]) == (0.25, "layers of sub-part 1/4")
    assert parse_progress(lines[1]) == (None, "posting")
    assert parse_progress("Traceback (most recent call last):") is None


def test_worker_environment_carries_the_addon_and_sys_path():
    from freecad_conformal import ADDON_ROOT

    assert str(ADDON_ROOT) == worker_environment()["PYTHONPATH"].split(":")[0]


def test_worker_sections_equal_in_process(pump_brep):
    inputs = sections_inputs(pump_brep)
    worker = WorkerProcess("sections", inputs).start()
    outcome = worker.wait(120)
    assert outcome.ok, outcome.traceback
    here = compute("sections", inputs)
    assert outcome.result["layers"] == here["layers"] > 3
    assert outcome.result["area"] == pytest.approx(here["area"], rel=1e-9)
    assert not worker.folder.exists()          # nothing left behind


def test_worker_error_is_one_line_with_the_traceback_apart(pump_brep):
    from freecad_conformal.settings.plan import PLAN_SETTINGS
    from freecad_conformal.settings.schema import defaults

    values = dict(defaults(PLAN_SETTINGS), layer_height=0.0)
    outcome = WorkerProcess("job", {"brep": pump_brep, "part": "nut", "values": values}) \
        .start().wait(120)
    assert not outcome.ok
    assert "layer height" in outcome.error and "\n" not in outcome.error
    assert "Traceback" in outcome.traceback


def test_cancel_ends_the_worker_at_once(pump_brep):
    from freecad_conformal.settings.plan import PLAN_SETTINGS
    from freecad_conformal.settings.schema import defaults

    values = dict(defaults(PLAN_SETTINGS), layer_height=0.1)
    worker = WorkerProcess("job", {"brep": pump_brep, "part": "nut", "values": values}).start()
    time.sleep(1.0)
    assert worker.running
    started = time.monotonic()
    worker.cancel()
    assert time.monotonic() - started < 5.0
    assert not worker.running and worker.process.returncode is not None
    assert worker.poll().cancelled and not worker.folder.exists()


@pytest.mark.slow
def test_job_paths_map_back_onto_the_part_as_modelled(parts_dir):
    """A table modelled lying on its side far off the platform is centred and stood up by
    the plan: its machine-frame paths are off the modelled table, mapped back they are on it."""
    import numpy as np

    from freecad_conformal.freecad_env import import_freecad
    from freecad_conformal.gui.path_display import frame_matrices, to_part_frame
    from freecad_conformal.objects.job_feature import compute_job
    from freecad_conformal.objects.toolpath_feature import toolpath_from_bytes
    from freecad_conformal.settings.plan import PLAN_SETTINGS
    from freecad_conformal.settings.schema import defaults
    from freecad_conformal.toolpath import KINDS

    App, Part = import_freecad()
    shape = Part.Shape()
    shape.read(str(parts_dir / "MODERN_Table_1.brep"))
    shape.rotate(App.Vector(0, 0, 0), App.Vector(1, 0, 0), 90.0)
    shape.translate(App.Vector(2000.0, 0.0, 0.0))
    values = dict(defaults(PLAN_SETTINGS), layer_height=1.5, bead_width=1.5, tilt=False)
    result = compute_job({"brep": shape.exportBrepToString(), "part": "table", "values": values},
                         lambda *_: None)
    toolpath = toolpath_from_bytes(result["toolpath"])
    matrices = frame_matrices(result["frame_subparts"], result["frames"])
    assert set(result["segment_subparts"]) <= set(matrices)
    on_part = to_part_frame(toolpath.points, toolpath.segment_index,
                            result["segment_subparts"], matrices)
    deposit = np.flatnonzero(toolpath.kind[toolpath.segment_index] == KINDS.index("deposit"))
    sample = deposit[:: max(1, len(deposit) // 150)]

    def inside(points):
        return np.mean([shape.isInside(App.Vector(*map(float, p)), 1.0, True) for p in points])

    assert inside(on_part[sample]) > 0.95
    assert inside(toolpath.points[sample]) < 0.5     # the machine frame is elsewhere

    # one time estimate: the Post of the Job's toolpath reports the Job's time
    posted = compute("post", {"toolpath": result["toolpath"], "machine": "trunnion_ac",
                              "dialect": None, "tolerance": 0.01, "angular_tolerance": 0.01},
                     lambda *_: None)
    assert posted["seconds"] == pytest.approx(result["seconds"], rel=1e-9)


def test_sections_that_miss_the_part_fail_rather_than_pass_empty(pump_brep):
    from freecad_conformal.errors import GeometryError

    inputs = {"brep": pump_brep, "mode": "cylindrical", "chord_tolerance": 0.01,
              "radii": [1000.0, 1001.0], "axis_point": (5000.0, 0.0, 0.0),
              "direction": (0.0, 0.0, 1.0)}
    with pytest.raises(GeometryError, match="no section: the cylinders of radii 1000 to 1001"):
        compute("sections", inputs)
