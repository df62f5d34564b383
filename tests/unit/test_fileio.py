"""Atomic writes: whole file or nothing, with ordinary permissions."""
import os
import stat

import pytest

from freecad_conformal.fileio import atomic_write, write_text_atomic


def test_written_file_has_umask_permissions(tmp_path):
    target = tmp_path / "a.ngc"
    write_text_atomic(target, "G0 X0\n")
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(target.stat().st_mode) == 0o666 & ~umask
    assert target.read_text() == "G0 X0\n"


def test_failure_leaves_neither_target_nor_temporary(tmp_path):
    target = tmp_path / "b.ngc"
    with pytest.raises(RuntimeError):
        with atomic_write(target) as handle:
            handle.write("half")
            raise RuntimeError("planner failed")
    assert list(tmp_path.iterdir()) == []


def test_failure_keeps_the_previous_file(tmp_path):
    target = tmp_path / "c.ngc"
    write_text_atomic(target, "old\n")
    with pytest.raises(ValueError):
        with atomic_write(target) as handle:
            handle.write("new")
            raise ValueError
    assert target.read_text() == "old\n"
