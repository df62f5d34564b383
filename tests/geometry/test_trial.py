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
