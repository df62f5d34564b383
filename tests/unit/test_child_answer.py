"""A child Python's answer that does not unpickle here is no answer: the caller computes in
place instead of failing (an exception without `__reduce__` once killed a plan so)."""
from __future__ import annotations

import textwrap

from freecad_conformal.child_python import ChildPython

REFUSAL = textwrap.dedent('''
    class Refused(Exception):
        """Pickled as Refused(message): rebuilding it misses `where` (TypeError)."""

        def __init__(self, machine, where):
            super().__init__(f"{machine}: {where}")
    ''')

CHILD = textwrap.dedent('''
    import pickle
    import sys

    from refusal import Refused

    pickle.dump((False, Refused("trunnion", "solid 1")), sys.stdout.buffer)
    ''')


def test_an_answer_that_does_not_unpickle_is_no_answer(tmp_path, monkeypatch):
    (tmp_path / "refusal.py").write_text(REFUSAL)
    (tmp_path / "unreadable_answer.py").write_text(CHILD)
    monkeypatch.setenv("PYTHONPATH", str(tmp_path))
    monkeypatch.syspath_prepend(str(tmp_path))      # the class is found here, as in a child
    child = ChildPython("unreadable_answer")
    assert child.answer() is None
