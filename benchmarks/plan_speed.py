"""Wall time of `plan` against PrusaSlicer's CLI on the same part, in the same run.

For every part in ../shared/parts, the built-in samples and the curved parts of our own
making (benchmarks/own_parts.py: a screw thread, a fan, a connecting rod, a pipe elbow, a
coil spring, a lofted transition, an ellipsoid on a pedestal): our plan in a fresh process (its
wall time, peak memory and time per stage: plan choice (decomposition or candidate
orientations, laid out, sliced and costed: jobs/plan.choose_plan, less the chosen plan's
layers), layers (the chosen plan's, whether the choice sliced them or the job), paths,
post, preview and files) and PrusaSlicer slicing the part's STL as modelled with the settings of
`benchmarks/compare_planar.py` (PRUSA_SETTINGS), timed the same way. Prints the ratio per part
and checks the goals of issue 21: plan <= 5x PrusaSlicer, no stage above 40 % of our total,
no part above 60 s, peak memory under 2 GB; and issue 16's: the plan choice with its layers
(everything before paths) within 20 s on every part (3 s on CrankArm).

Run: `.venv/bin/python benchmarks/plan_speed.py [--repeat N] [--freecad1] [PART ...]` (needs
prusa-slicer: `TMPDIR=/var/tmp apt-get install -y prusa-slicer`). With `--repeat N` each
part is planned and sliced N times, alternating, and the fastest run of each side is
reported (ours with its own stages): on a shared machine one run's load can move a
stage's share by 5 points either way. With `--freecad1` (as root) our side runs on
FreeCAD 1.0 (OCCT 7.8, Python 3.13), most users' FreeCAD, in the chroot of
`ci/freecad1.sh` (set up first: this checkout as committed); PrusaSlicer runs here.
"""
from __future__ import annotations

import argparse
import compileall
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

PARTS_DIR = ROOT.parent / "shared" / "parts"
from own_parts import OWN_PARTS  # noqa: E402  (B-spline-heavy parts of our own making)
SAMPLES = ("bracket", "jack", "hinge")
#: What each stage of ours is: (module, function) wrapped with a timer in the child process.
STAGES = {"plan choice": ("freecad_conformal.jobs.plan", "choose_plan"),
          "layers": ("freecad_conformal.jobs.plan", "plan_layers"),
          "paths": ("freecad_conformal.jobs.plan", "assemble"),
          "post": ("freecad_conformal.jobs.plan", "post_toolpath"),
          "preview": ("freecad_conformal.paths.preview", "render_png")}
RATIO_GOAL, STAGE_SHARE_GOAL, PART_SECONDS_GOAL, MEMORY_GOAL_MB = 5.0, 0.40, 60.0, 2048.0
#: Issue 16: the plan choice (everything before paths) per part, and on CrankArm.
CHOICE_SECONDS_GOAL, CHOICE_SECONDS_GOAL_BY_PART = 20.0, {"CrankArm": 3.0}


def child(part: str, out: str) -> None:
    """Plan one part here, timing each stage; print one JSON line."""
    import importlib

    spent: dict[str, float] = {name: 0.0 for name in STAGES}

    def timed(name, function):
        def wrapper(*args, **kwargs):
            start = time.perf_counter()
            try:
                return function(*args, **kwargs)
            finally:
                spent[name] += time.perf_counter() - start
        return wrapper

    for name, (module_name, attribute) in STAGES.items():
        module = importlib.import_module(module_name)
        setattr(module, attribute, timed(name, getattr(module, attribute)))
    # The choice slices its candidates; the chosen one's layers are the job's layers (run_job
    # reuses them), so their time is the layers stage's, the rest the choice's.
    search = importlib.import_module("freecad_conformal.jobs.search")
    sliced: dict[int, tuple[object, float]] = {}

    def slicing(sub, *args, **kwargs):
        start = time.perf_counter()
        try:
            return search_layers(sub, *args, **kwargs)
        finally:
            sliced[id(sub)] = (sub, time.perf_counter() - start)

    search_layers, search.plan_layers = search.plan_layers, slicing
    plan_module = importlib.import_module("freecad_conformal.jobs.plan")
    choose = plan_module.choose_plan
    chosen_layers = [0.0]

    def choosing(*args, **kwargs):
        choice = choose(*args, **kwargs)
        chosen_layers[0] += sum(sliced[id(sub)][1] for sub in choice.plan.subparts
                                if id(sub) in sliced and sliced[id(sub)][0] is sub)
        return choice

    plan_module.choose_plan = choosing
    from freecad_conformal.cli import main

    start = time.perf_counter()
    code = main(["plan", part, "-o", out])
    total = time.perf_counter() - start
    spent["plan choice"] -= chosen_layers[0]
    spent["layers"] += chosen_layers[0]
    peak_mb = _peak_mb()
    print(json.dumps({"code": code, "seconds": total, "stages": spent, "peak_mb": peak_mb}))
    # Ended as `python -m freecad_conformal` ends (`cli.leave`): the wall time is a user's.
    from freecad_conformal.cli import leave

    leave(0)


def _peak_mb() -> float:
    """This process's peak resident memory (MB). Linux's VmHWM, of this program's own
    memory: `ru_maxrss` survives exec, so a child started by this benchmark would report
    the benchmark's own peak when larger (194 MB for the wedge)."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                return float(line.split()[1]) / 1024.0
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


#: The FreeCAD 1.0 chroot (`ci/freecad1.sh`): its root, and where the checkout, its Python
#: and the shared parts are inside it.
CHROOT = Path(os.environ.get("ROOT", "/srv/trixie"))
CHROOT_PROJECT, CHROOT_PYTHON, CHROOT_PARTS = "/root/conformal", "/root/venv/bin/python", "/root/shared/parts"


def ours(part: str, work: Path, freecad1: bool = False) -> dict:
    """Our plan of `part` in a fresh process (on FreeCAD 1.0 in its chroot: `part` is then
    a path inside it, or a sample's name)."""
    started = time.perf_counter()
    command = [sys.executable, __file__, "--child", part, str(work / "ours.ngc")]
    if freecad1:
        # Straight into the chroot, mounted once (`_prepare_freecad1`): `ci/freecad1.sh run`
        # mounts and unmounts /proc, /sys and /dev each time, 40 ms that no user pays.
        command = ["chroot", str(CHROOT), "env", "HOME=/root", "TMPDIR=/var/tmp", CHROOT_PYTHON,
                   f"{CHROOT_PROJECT}/benchmarks/plan_speed.py", "--child", part,
                   "/var/tmp/plan_speed_ours.ngc"]
    run = subprocess.run(command, capture_output=True, text=True)
    wall = time.perf_counter() - started
    lines = [line for line in run.stdout.splitlines() if line.startswith("{")]
    if run.returncode != 0 or not lines:
        return {"error": (run.stderr.strip().splitlines() or ["failed"])[-1], "wall": wall}
    result = json.loads(lines[-1])
    result["wall"] = wall
    return result


def prusa(shape, work: Path) -> float | str:
    """PrusaSlicer's wall time slicing `shape` as modelled, or why it refused (a part resting
    on an edge has "no extrusions in the first layer"): the other parts are still timed."""
    from compare_planar import PRUSA_SETTINGS

    stl = work / "part.stl"
    shape.exportStl(str(stl))
    started = time.perf_counter()
    run = subprocess.run(["prusa-slicer", "--export-gcode", *PRUSA_SETTINGS, "--center",
                          "100,100", "-o", str(work / "prusa.gcode"), str(stl)],
                         capture_output=True, text=True)
    seconds = time.perf_counter() - started
    if run.returncode != 0:
        # Its reason, then "Object name: part.stl"; progress and trace lines go before.
        said = [line for line in run.stderr.splitlines()
                if line.strip() and not line.startswith("[") and not line.startswith("Object name")]
        return f"PrusaSlicer failed (exit {run.returncode}): {said[-1] if said else 'no message'}"
    return seconds


def _own_part(name: str, folder: Path) -> str:
    """A part of benchmarks/own_parts.py written as BREP, as a user's file would be."""
    path = folder / f"{name}.brep"
    OWN_PARTS[name]().exportBrep(str(path))
    return str(path)


def _prepare_freecad1() -> None:
    """Set the chroot up (this checkout as committed, the shared parts) and compile the
    package there once, as for this side; then mount what it needs for the whole run
    (`_release_freecad1` unmounts)."""
    for step in (["setup"], ["run", CHROOT_PYTHON, "-m", "compileall", "-q",
                             f"{CHROOT_PROJECT}/freecad_conformal"], ["mount"]):
        run = subprocess.run([str(ROOT / "ci" / "freecad1.sh"), *step], capture_output=True,
                             text=True)
        if run.returncode != 0:
            tail = (run.stderr.strip() or run.stdout.strip()).splitlines()[-5:]
            raise SystemExit(f"--freecad1: ci/freecad1.sh {step[0]} failed:\n" + "\n".join(tail))


def _release_freecad1() -> None:
    subprocess.run([str(ROOT / "ci" / "freecad1.sh"), "umount"], capture_output=True)


def _inside_chroot(part: str) -> str:
    """`part` as the chroot sees it: a shared part in its copy of them, an own part written
    under its /var/tmp (by `_own_part`), a sample's name as it is."""
    path = Path(part).resolve() if Path(part).exists() else Path(part)
    if path.parent == PARTS_DIR.resolve():
        return f"{CHROOT_PARTS}/{path.name}"
    if CHROOT in path.parents:
        return "/" + str(path.relative_to(CHROOT))
    if path.suffix:
        raise SystemExit(f"--freecad1: {part} is not in {PARTS_DIR} nor an own part")
    return part


def main(names: list[str], repeat: int = 1, freecad1: bool = False) -> int:
    if shutil.which("prusa-slicer") is None:
        print("prusa-slicer is not installed: TMPDIR=/var/tmp apt-get install -y prusa-slicer")
        return 1
    if freecad1 and os.geteuid() != 0:
        print("--freecad1 runs ci/freecad1.sh (a chroot): run as root")
        return 1
    # An installed package runs from bytecode (pip and FreeCAD's first import write it);
    # where PYTHONDONTWRITEBYTECODE is set (this machine's shells) every run would compile
    # the ~100 modules again first (65 ms of a 0.5 s plan of wedge_ok), which no user pays.
    compileall.compile_dir(str(ROOT / "freecad_conformal"), quiet=1)
    if freecad1:
        _prepare_freecad1()
        own_folder = CHROOT / "var" / "tmp" / "plan_speed_own"
        own_folder.mkdir(parents=True, exist_ok=True)
    else:
        own_folder = Path(tempfile.mkdtemp(prefix="plan_speed_own_"))
    try:
        return _measure(names, repeat, freecad1, own_folder)
    finally:
        if freecad1:
            _release_freecad1()


def _measure(names: list[str], repeat: int, freecad1: bool, own_folder: Path) -> int:
    """Time every part on both sides and print the table and the goals missed."""
    from freecad_conformal.geometry.samples import load_part

    parts = names or [str(p) for p in sorted(PARTS_DIR.glob("*"))
                      if p.suffix.lower() in (".step", ".brep")] + list(SAMPLES) + list(OWN_PARTS)
    parts = [_own_part(name, own_folder) if name in OWN_PARTS else name for name in parts]
    if freecad1:
        print("ours on FreeCAD 1.0 (ci/freecad1.sh's chroot), PrusaSlicer here")
    print(f"{'part':22} {'ours s':>8} {'prusa s':>8} {'ratio':>6} {'peak MB':>8}  "
          "largest stage        stages (s)")
    misses = []
    for part in parts:
        shape, name = load_part(part)
        runs, slices = [], []
        with tempfile.TemporaryDirectory() as folder:
            work = Path(folder)
            for _ in range(repeat):
                runs.append(ours(_inside_chroot(part) if freecad1 else part, work, freecad1))
                slices.append(prusa(shape, work))
        failed = [run for run in runs if "error" in run]
        mine = failed[0] if failed else min(runs, key=lambda run: run["wall"])
        if "error" in mine:
            print(f"{name:22} failed after {mine['wall']:.1f} s: {mine['error']}")
            misses.append(f"{name}: failed")
            continue
        refused = [s for s in slices if isinstance(s, str)]
        if refused:
            print(f"{name:22} {mine['wall']:8.2f}  no peer time: {refused[0]}")
            misses.append(f"{name}: no ratio ({refused[0]})")
            continue
        theirs = min(slices)
        wall, stages = mine["wall"], mine["stages"]
        largest = max(stages, key=stages.get)
        share = stages[largest] / mine["seconds"]
        ratio = wall / theirs
        print(f"{name:22} {wall:8.2f} {theirs:8.2f} {ratio:6.1f} {mine['peak_mb']:8.0f}  "
              f"{largest:12} {share:5.0%}   "
              + ", ".join(f"{k} {v:.1f}" for k, v in stages.items()))
        if ratio > RATIO_GOAL:
            misses.append(f"{name}: {ratio:.1f}x PrusaSlicer (goal {RATIO_GOAL:g}x)")
        if share > STAGE_SHARE_GOAL:
            misses.append(f"{name}: {largest} is {share:.0%} of the time (goal {STAGE_SHARE_GOAL:.0%})")
        if wall > PART_SECONDS_GOAL:
            misses.append(f"{name}: {wall:.0f} s (goal {PART_SECONDS_GOAL:g} s)")
        choice_goal = CHOICE_SECONDS_GOAL_BY_PART.get(name, CHOICE_SECONDS_GOAL)
        before_paths = stages["plan choice"] + stages["layers"]
        if before_paths > choice_goal:
            misses.append(f"{name}: plan choice and layers {before_paths:.1f} s "
                          f"(goal {choice_goal:g} s)")
        if mine["peak_mb"] > MEMORY_GOAL_MB:
            misses.append(f"{name}: {mine['peak_mb']:.0f} MB peak (goal {MEMORY_GOAL_MB:g} MB)")
    print("goals met" if not misses else "goals missed:\n  " + "\n  ".join(misses))
    return 0


if __name__ == "__main__":
    if sys.argv[1:2] == ["--child"]:
        child(sys.argv[2], sys.argv[3])
    else:
        parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
        parser.add_argument("parts", nargs="*", help="parts (files, samples or own parts); "
                            "default: all")
        parser.add_argument("--repeat", type=int, default=1,
                            help="runs per part and side; the fastest of each is reported")
        parser.add_argument("--freecad1", action="store_true",
                            help="plan on FreeCAD 1.0 in ci/freecad1.sh's chroot (root)")
        arguments = parser.parse_args()
        if arguments.repeat < 1:
            parser.error(f"--repeat must be at least 1, got {arguments.repeat}")
        sys.exit(main(arguments.parts, arguments.repeat, arguments.freecad1))
