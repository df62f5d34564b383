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
