"""Run checks inside the real FreeCAD (GUI under Xvfb, or freecadcmd) with the addon installed.

The addon is installed the way a user's Addon Manager would: a temporary FreeCAD user home
(FreeCAD 0.20 honours ``$FREECAD_USER_HOME`` as its user data folder) whose ``Mod/Conformal``
is a symlink to this repository. A check script defines ``main(params) -> dict``; the runner
(`gui_runner.py`, executed by FreeCAD) calls it once the event loop is running, writes the dict
as JSON and quits. Failures raise `FreeCADRunError` with the FreeCAD log (its stdout/stderr).
"""
from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
PROJECT_ROOT = HERE.parent.parent
RUNNER = HERE / "gui_runner.py"

#: A cold FreeCAD GUI start takes 5-10 s here; each check script aims at < 60 s. The slack is
#: for a 2-core machine shared by several test runs.
GUI_TIMEOUT_S = 150.0
#: Xvfb screen large enough for the main window with a docked panel.
XVFB_SCREEN = "-screen 0 1600x1000x24"
#: Seconds before the timeout at which FreeCAD dumps its Python stacks into the log.
WATCHDOG_MARGIN_S = 15.0
#: Lines of FreeCAD output quoted in a failure message.
LOG_TAIL_LINES = 80


class FreeCADRunError(AssertionError):
    """FreeCAD failed, timed out or its check script raised; the message holds its log."""


def require_freecad_gui() -> None:
    """Skip unless the FreeCAD GUI and Xvfb are installed (./dev.sh test installs both)."""
    for program in ("freecad", "xvfb-run"):
        if shutil.which(program) is None:
            pytest.skip(f"{program} is not installed (./dev.sh test installs it)")


def make_user_home(root: Path) -> Path:
    """A fresh FreeCAD user home under `root` with Mod/Conformal linked to this repository."""
    home = root / "freecad-home"
    mod = home / "Mod"
    mod.mkdir(parents=True, exist_ok=True)
    link = mod / "Conformal"
    if not link.exists():
        link.symlink_to(PROJECT_ROOT, target_is_directory=True)
    # The FreeCAD GUI clears PYTHONPATH; Python's user site (under HOME) still loads .pth
    # files, which is also where `pip install --user shapely` would put a user's packages.
    version = f"python{sys.version_info.major}.{sys.version_info.minor}"
    user_site = home / ".local" / "lib" / version / "site-packages"
    user_site.mkdir(parents=True, exist_ok=True)
    (user_site / "conformal-test-venv.pth").write_text(
        sysconfig.get_paths()["purelib"] + "\n", encoding="utf-8")
    return home


def freecad_environment(home: Path) -> dict[str, str]:
    """Environment for a FreeCAD process: isolated user home and tool library, the test
    venv's packages visible (shapely is not a Debian dependency of FreeCAD): through
    PYTHONPATH for freecadcmd, through the user site (see make_user_home) for the GUI."""
    env = dict(os.environ)
    site = sysconfig.get_paths()["purelib"]
    env.update({
        "FREECAD_USER_HOME": str(home),
        "HOME": str(home),
        "CONFORMAL_USER_DIR": str(home / "conformal-user"),
        "QTWEBENGINE_DISABLE_SANDBOX": "1",
        "PYTHONPATH": os.pathsep.join(p for p in (site, env.get("PYTHONPATH", "")) if p),
        "PYTHONDONTWRITEBYTECODE": "1",
    })
    return env


def _run(command: list[str], env: dict[str, str], timeout: float, cwd: Path) -> tuple[int, str]:
    """Run `command` in its own process group; on timeout kill that group (Xvfb and FreeCAD)."""
    process = subprocess.Popen(command, env=env, cwd=cwd, stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, text=True, errors="replace",
                               start_new_session=True)
    try:
        output, _ = process.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        output, _ = process.communicate()
        raise FreeCADRunError(f"{command[:4]} timed out after {timeout:.0f} s\n{_tail(output)}")
    return process.returncode, output


def _tail(log: str) -> str:
    lines = log.splitlines()
    return "FreeCAD log (last lines):\n" + "\n".join(lines[-LOG_TAIL_LINES:])


#: A check that failed once in this pytest session fails at once for the other tests
#: sharing its module fixture (pytest would otherwise rerun a failing fixture per test).
_FAILED: dict[str, FreeCADRunError] = {}


def run_gui_check(check_script: Path, tmp_path: Path, params: dict | None = None,
                  timeout: float = GUI_TIMEOUT_S) -> dict:
    """Run `check_script`'s main(params) in the FreeCAD GUI under Xvfb; return its dict."""
    require_freecad_gui()
    if str(check_script) in _FAILED:
        raise _FAILED[str(check_script)]
    try:
        return _run_gui_check(check_script, tmp_path, params, timeout)
    except FreeCADRunError as exc:
        _FAILED[str(check_script)] = exc
        raise


def _run_gui_check(check_script: Path, tmp_path: Path, params: dict | None,
                   timeout: float) -> dict:
    home = make_user_home(tmp_path)
    result_path = tmp_path / "gui-result.json"
    env = freecad_environment(home)
    env.update({
        "CONFORMAL_GUI_CHECK": str(check_script),
        "CONFORMAL_GUI_RESULT": str(result_path),
        "CONFORMAL_GUI_PARAMS": json.dumps(params or {}),
        "CONFORMAL_GUI_SUPPORT": str(HERE),
        "CONFORMAL_GUI_WATCHDOG": str(max(timeout - WATCHDOG_MARGIN_S, 1.0)),
        "CONFORMAL_GUI_STACKS": str(tmp_path / "gui-stacks.txt"),
    })
    command = ["xvfb-run", "-a", "-s", XVFB_SCREEN, "freecad", str(RUNNER)]
    try:
        code, log = _run(command, env, timeout, tmp_path)
    except FreeCADRunError as exc:
        stacks = tmp_path / "gui-stacks.txt"
        text = stacks.read_text(encoding="utf-8", errors="replace") if stacks.exists() else ""
        raise FreeCADRunError(f"{exc}\nPython stacks in FreeCAD before the timeout:\n{text}") from None
    if not result_path.exists():
        raise FreeCADRunError(f"FreeCAD exited with {code} without a result\n{_tail(log)}")
    result = json.loads(result_path.read_text(encoding="utf-8"))
    if result.get("error"):
        raise FreeCADRunError(f"check {check_script.name} failed in FreeCAD:\n"
                              f"{result['error']}\n{_tail(log)}")
    result["log"] = log
    return result


def run_freecadcmd(arguments: list[str], tmp_path: Path,
                   timeout: float = GUI_TIMEOUT_S) -> tuple[int, str]:
    """Run freecadcmd with the addon installed in a temporary user home; (exit code, log)."""
    if shutil.which("freecadcmd") is None:
        pytest.skip("freecadcmd is not installed (./dev.sh test installs FreeCAD)")
    env = freecad_environment(make_user_home(tmp_path))
    return _run(["freecadcmd", *arguments], env, timeout, tmp_path)


def image_statistics(path: Path) -> dict:
    """Size, number of distinct colours and the share of the most common colour."""
    from PIL import Image

    with Image.open(path) as image:
        rgb = image.convert("RGB")
        colours = rgb.getcolors(maxcolors=rgb.width * rgb.height)
        width, height = rgb.size
    dominant = max(count for count, _ in colours)
    return {"width": width, "height": height, "colours": len(colours),
            "dominant_share": dominant / (width * height)}


#: An image whose most common colour covers more than this share of the pixels shows
#: (almost) nothing: a blank view, a black GL grab or an empty widget.
MAX_DOMINANT_SHARE = 0.97
#: Background plus at least two drawn colours (line renderings without anti-aliasing have
#: only a handful of flat colours).
MIN_COLOURS = 3


def assert_image_has_content(path: Path, min_width: int = 200, min_height: int = 150) -> dict:
    """Fail on a missing, tiny, blank or all-one-colour image; return its statistics."""
    assert path.is_file(), f"screenshot {path} was not written"
    stats = image_statistics(path)
    assert stats["width"] >= min_width and stats["height"] >= min_height, (path, stats)
    assert stats["colours"] >= MIN_COLOURS, f"{path.name} has only {stats['colours']} colours"
    assert stats["dominant_share"] <= MAX_DOMINANT_SHARE, (
        f"{path.name} is {stats['dominant_share']:.1%} one colour: blank")
    return stats

