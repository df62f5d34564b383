"""Support-free multi-axis plan against PrusaSlicer (planar, with and without supports).

For each part: export STL, slice it with PrusaSlicer's CLI in each of the six axis-aligned
orientations with supports on, keep its best (least filament), slice that orientation again
with supports off, and read filament volume, support-only extrusion (";TYPE:Support
material" and its interface) and estimated time from the G-code. Then plan the part with
this project (decomposition, layers, paths) at the same settings and print both with ratios.

Same settings on both sides: layer 0.2 mm, nozzle 0.4 mm, 2 perimeters, 20 % infill, three
solid top/bottom layers, bead width 0.45 mm (PrusaSlicer's automatic width for a 0.4 mm
nozzle), PrusaSlicer's default speeds per role (external perimeter 30, perimeters 60, sparse
infill 80, solid infill 20, travel 130 mm/s), its time-estimate limits (acceleration
1500 mm/s², jerk 10 mm/s) and its cooling slowdown (layers under 5 s, not below 10 mm/s).

Needs the Debian package prusa-slicer (`TMPDIR=/var/tmp apt-get install -y prusa-slicer`).
Run: `.venv/bin/python benchmarks/compare_planar.py [jack bracket hinge CrankArm]`.
"""
from __future__ import annotations

import math
import re
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from freecad_conformal.errors import ConformalError  # noqa: E402
from freecad_conformal.geometry import samples  # noqa: E402
from freecad_conformal.geometry.solids import load_shape  # noqa: E402
from freecad_conformal.paths.assemble import Feeds, PathSettings  # noqa: E402
from freecad_conformal.paths.fill2d import FillSettings  # noqa: E402
from freecad_conformal.paths.timing import estimate_time  # noqa: E402
from freecad_conformal.planning.decompose import decompose  # noqa: E402
from freecad_conformal.planning.job import PlanOptions, run_job  # noqa: E402
from freecad_conformal.planning.layers import LayerSettings  # noqa: E402

PARTS_DIR = ROOT.parent / "shared" / "parts"
LAYER, NOZZLE, PERIMETERS, INFILL, BEAD = 0.2, 0.4, 2, 0.20, 0.45
#: PrusaSlicer 2.5 defaults (mm/s) and its time-estimate machine limits.
SPEEDS = {"external_perimeter": 30.0, "perimeter": 60.0, "infill": 80.0, "solid_infill": 20.0,
          "travel": 130.0}
ACCELERATION, JERK = 1500.0, 10.0
ORIENTATIONS = {"as modelled": [], "rotate-x 90": ["--rotate-x", "90"],
                "rotate-x 180": ["--rotate-x", "180"], "rotate-x -90": ["--rotate-x", "-90"],
                "rotate-y 90": ["--rotate-y", "90"], "rotate-y -90": ["--rotate-y", "-90"]}
FILAMENT_AREA = math.pi * 1.75 ** 2 / 4.0


@dataclass
class Slice:
    orientation: str
    volume_cm3: float
    support_cm3: float
    seconds: float


def parse_time(text: str) -> float:
    match = re.search(r"estimated printing time \(normal mode\) = (.*)", text)
    units = {"d": 86400, "h": 3600, "m": 60, "s": 1}
    return float(sum(int(n) * units[u] for n, u in re.findall(r"(\d+)([dhms])", match.group(1))))


def support_volume(text: str) -> float:
    """cm³ extruded in ;TYPE:Support material (and interface) blocks (relative E)."""
    total, inside = 0.0, False
    for line in text.splitlines():
        if line.startswith(";TYPE:"):
            inside = line.startswith(";TYPE:Support material")
        elif inside and line.startswith("G1") and " E" in line:
            value = float(line.split(" E")[1].split()[0])
            total += max(value, 0.0)
    return total * FILAMENT_AREA / 1000.0


def prusa_slice(stl: Path, orientation: str, supports: bool, work: Path) -> Slice:
    out = work / f"{stl.stem}_{orientation.replace(' ', '_')}_{int(supports)}.gcode"
    command = ["prusa-slicer", "--export-gcode", "--layer-height", str(LAYER),
               "--nozzle-diameter", str(NOZZLE), "--perimeters", str(PERIMETERS),
               "--fill-density", f"{INFILL * 100:g}%", "--use-relative-e-distances",
               "--center", "100,100", *ORIENTATIONS[orientation], "-o", str(out), str(stl)]
    if supports:
        command.insert(2, "--support-material")
    subprocess.run(command, check=True, capture_output=True, timeout=1800)
    text = out.read_text()
    volume = float(re.search(r"filament used \[cm3\] = ([\d.]+)", text).group(1))
    return Slice(orientation, volume, support_volume(text), parse_time(text))


def load(name: str):
    if name in samples.SAMPLES:
        return samples.SAMPLES[name]()
    return load_shape(PARTS_DIR / f"{name}.brep")


def ours(shape, name: str):
    feeds = Feeds(**{k: v * 60.0 for k, v in SPEEDS.items()})
    options = PlanOptions(layers=LayerSettings(thickness=LAYER), bead_width=BEAD,
                          paths=PathSettings(fill=FillSettings(bead_width=BEAD, perimeters=PERIMETERS,
                                                               density=INFILL), feeds=feeds))
    started = time.perf_counter()
    plan = decompose(shape)
    result = run_job(shape, plan, options, part=name)
    seconds = estimate_time(result.assembly.toolpath, ACCELERATION, JERK)
    return result, seconds, time.perf_counter() - started


def hms(seconds: float) -> str:
    whole = int(round(seconds))
    return f"{whole // 3600}h{whole // 60 % 60:02d}m"


def main(names: list[str]) -> int:
    if shutil.which("prusa-slicer") is None:
        print("prusa-slicer is not installed: TMPDIR=/var/tmp apt-get install -y prusa-slicer")
        return 2
    rows = []
    with tempfile.TemporaryDirectory(prefix="compare_planar_") as folder:
        work = Path(folder)
        for name in names:
            shape = load(name)
            stl = work / f"{name}.stl"
            shape.exportStl(str(stl))
            with_support = [prusa_slice(stl, o, True, work) for o in ORIENTATIONS]
            best = min(with_support, key=lambda s: s.volume_cm3)
            bare = prusa_slice(stl, best.orientation, False, work)
            try:
                result, our_time, wall = ours(shape, name)
            except ConformalError as exc:
                print(f"{name}: no plan for {PlanOptions().machine}: {exc}", flush=True)
                continue
            rows.append((name, best, bare, result, our_time, wall))
            print(f"{name}: {len(result.subparts)} sub-parts, planned in {wall:.1f} s", flush=True)
    print()
    print(f"{'part':<10} {'PS best orientation':<20} {'PS+sup cm3':>10} {'sup cm3':>8} {'PS-sup cm3':>10} "
          f"{'ours cm3':>9} {'ours/PS-sup':>11} {'ours/PS+sup':>11} | {'PS+sup':>7} {'PS-sup':>7} "
          f"{'ours':>7} {'t/PS-sup':>8} {'t/PS+sup':>8} | {'our support':>11}")
    for name, best, bare, result, our_time, _ in rows:
        ours_cm3 = result.material_volume / 1000.0
        support = result.plan.support_area
        print(f"{name:<10} {best.orientation:<20} {best.volume_cm3:>10.2f} {best.support_cm3:>8.2f} "
              f"{bare.volume_cm3:>10.2f} {ours_cm3:>9.2f} {ours_cm3 / bare.volume_cm3:>11.3f} "
              f"{ours_cm3 / best.volume_cm3:>11.3f} | {hms(best.seconds):>7} {hms(bare.seconds):>7} "
              f"{hms(our_time):>7} {our_time / bare.seconds:>8.3f} {our_time / best.seconds:>8.3f} | "
              f"{'none' if support <= 0 else f'{support:.0f} mm2':>11}")
    print("\nPS = PrusaSlicer (its estimate); ours = plan material (bead x layer x length) and the "
          "same time model (trapezoids, jerk 10 mm/s, acceleration 1500 mm/s2, 5 s layer cooling)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:] or ["jack", "bracket", "hinge", "CrankArm"]))
