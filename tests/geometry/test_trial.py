"""The trial child starts before it is asked anything, and leaves quietly when it is not."""
from __future__ import annotations

from freecad_conformal.decomposition.trial import Trial


def test_a_child_never_asked_exits_cleanly_when_its_input_closes():
    trial = Trial()
    process = trial._process
    process.stdin.close()
    assert process.wait(timeout=60) == 0
    assert process.stdout.read() == b""
    process.stdout.close()


def test_stopping_a_child_never_asked_ends_it():
    trial = Trial()
    trial.stop()
    assert trial._process.poll() is not None


def test_the_child_runs_this_package_whatever_folder_it_is_started_from(tmp_path, monkeypatch):
    # `python -m` puts the working folder first on the path: a copy of the package there
    # (a user's checkout of another version) must not be the one that answers.
    decoy = tmp_path / "freecad_conformal"
    decoy.mkdir()
    (decoy / "__init__.py").write_text("raise SystemExit(3)\n")
    monkeypatch.chdir(tmp_path)
    trial = Trial()
    trial._process.stdin.close()
    assert trial._process.wait(timeout=60) == 0
    trial._process.stdout.close()


def test_a_pool_worker_starts_no_child():
    # batch's workers already fill the cores, and a stopped part's process leaves no child
    import multiprocessing

    from freecad_conformal.child_python import can_start_child

    assert can_start_child()
    with multiprocessing.get_context("spawn").Pool(1) as pool:
        assert pool.apply(can_start_child) is False


def _t_block_spec():
    """(planner, direction, written) for planning the T sample as placed (its arms split
    off)."""
    import math

    import numpy as np

    from freecad_conformal.decomposition.planner import Planner
    from freecad_conformal.geometry.occ_binary import to_binary
    from freecad_conformal.geometry.samples import SAMPLES

    solid = SAMPLES["t_block"]().Solids[0]
    planner = Planner(solid, 0, math.radians(45), "true-direction", None, 20)
    return planner, np.array([0.0, 0.0, 1.0]), to_binary(solid)


def test_a_child_given_the_solid_but_never_asked_exits_cleanly():
    _, _, written = _t_block_spec()
    trial = Trial()
    trial.prepare(written)
    trial._child._writer.join(timeout=60)
    trial._process.stdin.close()          # the parent closes its input after the first part
    assert trial._process.wait(timeout=60) == 0
    assert trial._process.stdout.read() == b""
    trial._process.stdout.close()


def test_a_prepared_child_plans_the_pieces_this_process_would():
    """The child meshes the solid it was sent before it is asked; its pieces are those
    planned here from the same bytes, to the last bit."""
    from freecad_conformal.decomposition.planner import Piece
    from freecad_conformal.decomposition.trial import planned, trial_spec

    planner, direction, written = _t_block_spec()
    trial = Trial()
    trial.prepare(written)
    trial.plan(planner, direction, written)
    pieces, notes = trial.result()
    here, here_notes = planned(trial_spec(planner, direction, written))
    here = [Piece.from_data(item) for item in here]
    assert notes == here_notes and len(pieces) == len(here) >= 2
    for a, b in zip(pieces, here):
        assert (a.shape.Volume, a.overhang) == (b.shape.Volume, b.overhang)
        assert [tuple(v.Point) for v in a.shape.Vertexes] == [tuple(v.Point) for v in b.shape.Vertexes]


def test_a_child_asked_without_being_sent_the_solid_first_still_answers():
    planner, direction, written = _t_block_spec()
    trial = Trial()
    trial.plan(planner, direction, written)
    answer = trial.result()
    assert answer is not None and len(answer[0]) >= 2


def test_a_child_asked_about_another_solid_than_it_was_sent_plans_that_one():
    import math

    from freecad_conformal.geometry.occ_binary import to_binary
    from freecad_conformal.geometry.samples import SAMPLES

    planner, direction, written = _t_block_spec()
    other = SAMPLES["l_block"]().Solids[0]
    trial = Trial()
    trial.prepare(written)
    trial.plan(planner, direction, to_binary(other))
    pieces, _ = trial.result()
    assert math.isclose(sum(p.shape.Volume for p in pieces), other.Volume, rel_tol=1e-9)
    assert not math.isclose(other.Volume, planner.solid.Volume, rel_tol=1e-3)


def test_a_child_sent_an_unreadable_solid_reports_the_error_when_asked():
    import pytest

    from freecad_conformal.errors import GeometryError

    planner, direction, _ = _t_block_spec()
    trial = Trial()
    trial.prepare(b"not a shape")
    trial.plan(planner, direction, b"not a shape")
    with pytest.raises(GeometryError, match="in the child"):
        trial.result()


def test_the_child_meshes_at_the_deflection_the_unmeshed_solid_gives():
    # `BoundBox` reads a triangulation once there is one (the dome's box shrinks with its
    # mesh): the child's pieces must be meshed as a child that meshed after the request did.
    from freecad_conformal.decomposition.trial import prepared
    from freecad_conformal.geometry.occ_binary import from_binary, to_binary
    from freecad_conformal.geometry.samples import SAMPLES
    from freecad_conformal.geometry.surface_mesh import RELATIVE_DEFLECTION, mesh_deflection

    written = to_binary(SAMPLES["domed_cylinder"]().Solids[0])
    _, solid, deflection = prepared(written)
    assert deflection == mesh_deflection(from_binary(written).Solids[0])
    # Meshed, its box is read from the mesh and would ask for another; the deflection is
    # read once per shape, before.
    assert deflection != RELATIVE_DEFLECTION * solid.BoundBox.DiagonalLength
    assert deflection == mesh_deflection(solid)


def test_an_early_trial_is_taken_for_its_solid_or_a_copy_left_in_place_only(monkeypatch):
    """The plan search begins the trial on the part's solid; the decomposition then plans
    the copy the placement made of it (`turn_up`), which must take it, while a moved copy or
    another solid must not (their plans come from their own bytes)."""
    import freecad_conformal.decomposition.trial as module
    from freecad_conformal.freecad_env import import_freecad
    from freecad_conformal.geometry.occ_binary import to_binary
    from freecad_conformal.geometry.samples import SAMPLES
    from freecad_conformal.jobs.placement import turn_up

    App, _ = import_freecad()
    monkeypatch.setattr(module, "can_start_child", lambda: False)   # no child: bytes only
    shape = SAMPLES["domed_cylinder"]()
    solid = shape.Solids[0]
    early = module.EarlyTrial(solid)
    assert early.written == to_binary(solid)
    in_place = turn_up(shape, (0.0, 0.0, 1.0))[0].Solids[0]
    assert not in_place.isSame(solid)
    moved = solid.copy()
    moved.translate(App.Vector(0.0, 0.0, 1e-3))
    turned = turn_up(shape, (0.0, 0.0, -1.0))[0].Solids[0]
    for other in (moved, turned, SAMPLES["t_block"]().Solids[0]):
        assert early.take(other) is None
    assert early.take(in_place) == (early.written, None)
    assert early.take(solid) == (early.written, None)


def test_an_early_trials_child_is_handed_over_once_and_stopped_when_not_taken():
    from freecad_conformal.decomposition.trial import EarlyTrial
    from freecad_conformal.geometry.samples import SAMPLES

    solid = SAMPLES["t_block"]().Solids[0]
    early = EarlyTrial(solid)
    written, trial = early.take(solid)
    assert trial is not None and trial._process.poll() is None
    assert early.take(solid) == (written, None)      # the child went with the first take
    early.stop()                                     # not this one's to stop any more
    assert trial._process.poll() is None
    trial.stop()
    unused = EarlyTrial(solid)
    process = unused._trial._process
    unused.stop()
    assert process.poll() is not None
