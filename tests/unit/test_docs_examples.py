"""The command examples of docs/process.md run as pasted (shell quoting included)."""
from __future__ import annotations

import re
import shlex
from pathlib import Path

from freecad_conformal.cli import main

DOCS = Path(__file__).resolve().parents[2] / "docs" / "process.md"


def _commands(text: str, sub: str) -> list[list[str]]:
    """Every `python -m freecad_conformal doe <sub>` line of the fenced blocks, joined
    over backslash continuations and split as a POSIX shell would."""
    blocks = re.findall(r"```[^\n]*\n(.*?)```", text, flags=re.S)
    lines = "\n".join(blocks).replace("\\\n", " ").splitlines()
    return [shlex.split(line)[3:] for line in lines
            if line.strip().startswith(f"python -m freecad_conformal doe {sub} ")]


def test_doe_design_example_runs(tmp_path, monkeypatch):
    commands = _commands(DOCS.read_text(encoding="utf-8"), "design")
    assert commands, "docs/process.md has no doe design example"
    monkeypatch.chdir(tmp_path)
    for argv in commands:
        assert main(argv) == 0, argv
    assert (tmp_path / "runs.csv").exists() and (tmp_path / "study.json").exists()
    assert "UV power" in (tmp_path / "study.json").read_text()
