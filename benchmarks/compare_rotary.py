"""Mandrel build versus a planar slicer (METHODS section 5) on the same spring, same run.

Builds a helical spring as a B-rep (default: inner radius 10 mm, pitch 8 mm, 5 turns,
3 × 3 mm section, axis along X), plans it on the rotary_mandrel machine (our G-code, true
rotary A and rotation-as-Y mappings) and slices its STL with PrusaSlicer with supports at the
same layer height, bead width and speeds (METHODS: print 2000 mm/min, travel 2400 mm/min,
200 °C, 0.4 mm nozzle; 100 % infill so both build the same solid unless --infill says
otherwise). Prints G-code bytes, block count, material and estimated time side by side, and
the ratios against the published goal (file at most 1/300 of the planar slicer's, time
below it; published: 36 KB versus 29 565 KB, 217 min versus 327 min).

Run: .venv/bin/python benchmarks/compare_rotary.py [--layer 0.3] [--turns 5] [--keep DIR]
"""
from __future__ import annotations

import argparse
import math
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))   # run from anywhere

from freecad_conformal.jobs.mandrel import (  # noqa: E402
    PRINT_FEED, TRAVEL_FEED, band_inclination, plan_mandrel, spring_solid)

FILAMENT = 1.75
TEMPERATURE = 200


def count_blocks(text: str) -> int:
    """Motion blocks (G0/G1/G2/G3 lines) of a program."""
    return sum(1 for line in text.splitlines() if re.match(r"\s*G[0-3](\s|$)", line))


def prusa_time_minutes(text: str) -> float | None:
    """PrusaSlicer's '; estimated printing time (normal mode) = 1h 2m 3s' in minutes."""
    match = re.search(r"estimated printing time \(normal mode\) = ([^\n]+)", text)
    if not match:
        return None
    units = {"d": 1440.0, "h": 60.0, "m": 1.0, "s": 1.0 / 60.0}
    return sum(float(v) * units[u] for v, u in re.findall(r"(\d+)([dhms])", match.group(1)))


def prusa_material_mm3(text: str) -> float | None:
    match = re.search(r"filament used \[mm3\] = ([\d.]+)", text)
    if match:
        return float(match.group(1))
    match = re.search(r"filament used \[mm\] = ([\d.]+)", text)
    return float(match.group(1)) * math.pi * FILAMENT ** 2 / 4 if match else None


def run_prusa(stl: Path, out: Path, layer: float, width: float, infill: int) -> subprocess.CompletedProcess:
    speed = PRINT_FEED / 60.0
    args = ["prusa-slicer", "--export-gcode", str(stl), "--output", str(out),
            "--support-material", "--layer-height", str(layer), "--first-layer-height", str(layer),
            "--nozzle-diameter", "0.4", "--extrusion-width", str(width),
            "--filament-diameter", str(FILAMENT), "--temperature", str(TEMPERATURE),
            "--first-layer-temperature", str(TEMPERATURE), "--fill-density", f"{infill}%",
            "--fill-pattern", "rectilinear",
            "--travel-speed", f"{TRAVEL_FEED / 60.0:g}", "--first-layer-speed", f"{speed:g}",
            "--gcode-flavor", "marlin2", "--bed-shape", "0x0,250x0,250x250,0x250",
            "--center", "125,125"]
    for key in ("perimeter-speed", "small-perimeter-speed", "external-perimeter-speed",
                "infill-speed", "solid-infill-speed", "top-solid-infill-speed",
                "support-material-speed", "support-material-interface-speed", "bridge-speed",
                "gap-fill-speed"):
        args += [f"--{key}", f"{speed:g}"]
    return subprocess.run(args, capture_output=True, text=True, timeout=1800)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--radius", type=float, default=10.0, help="spring inner radius (mm)")
    parser.add_argument("--pitch", type=float, default=8.0)
    parser.add_argument("--turns", type=float, default=5.0)
    parser.add_argument("--section", type=float, default=3.0, help="square section side (mm)")
    parser.add_argument("--layer", type=float, default=0.3)
    parser.add_argument("--width", type=float, default=0.4)
    parser.add_argument("--infill", type=int, default=100, help="PrusaSlicer infill %% (default 100)")
    parser.add_argument("--keep", type=Path, help="keep the STL and programs in this folder")
    args = parser.parse_args()

    work = Path(tempfile.mkdtemp(prefix="compare_rotary_")) if args.keep is None else args.keep
    work.mkdir(parents=True, exist_ok=True)
    spring = spring_solid(args.radius, args.pitch, args.turns, args.section, args.section)
    print(f"spring: inner radius {args.radius:g} mm, pitch {args.pitch:g} mm, {args.turns:g} turns, "
          f"{args.section:g} x {args.section:g} mm; volume {spring.Volume:.1f} mm3; band "
          f"inclination α = {math.degrees(band_inclination(args.pitch, args.radius)):.3f}°")

    rows = []
    for mapping in ("rotary", "linear"):
        start = time.perf_counter()
        result = plan_mandrel(spring, "rotary_mandrel", "fdm_0p4", args.layer,
                              work / f"spring_{mapping}.gcode", mapping=mapping, width=args.width,
                              part="spring")
        elapsed = time.perf_counter() - start
        rows.append((f"ours ({mapping})", len(result.gcode.encode()), result.blocks,
                     result.material_volume, result.time_s / 60.0, elapsed))

    stl = work / "spring.stl"
    spring.exportStl(str(stl))
    prusa = None
    if shutil.which("prusa-slicer") is None:
        print("PrusaSlicer is MISSING: install it (Debian: TMPDIR=/var/tmp apt-get install -y "
              "prusa-slicer) to measure the peer; only our numbers are shown")
    else:
        start = time.perf_counter()
        done = run_prusa(stl, work / "spring_prusa.gcode", args.layer, args.width, args.infill)
        elapsed = time.perf_counter() - start
        if done.returncode != 0:
            print(f"PrusaSlicer failed (exit {done.returncode}):\n{done.stderr[-2000:]}")
        else:
            text = (work / "spring_prusa.gcode").read_text()
            prusa = (f"PrusaSlicer {args.infill}% + supports", len(text.encode()),
                     count_blocks(text), prusa_material_mm3(text), prusa_time_minutes(text), elapsed)
            rows.append(prusa)

    print(f"\n{'program':<32}{'bytes':>14}{'KB':>10}{'blocks':>10}{'material mm3':>14}"
          f"{'est. min':>10}{'plan s':>9}")
    for name, size, blocks, material, minutes, elapsed in rows:
        mat = f"{material:.1f}" if material is not None else "?"
        est = f"{minutes:.1f}" if minutes is not None else "?"
        print(f"{name:<32}{size:>14,}{size / 1024:>10.1f}{blocks:>10,}{mat:>14}{est:>10}{elapsed:>9.1f}")
    if prusa is not None:
        for name, size, blocks, material, minutes, _ in rows[:2]:
            size_ratio = prusa[1] / size
            time_ratio = (minutes / prusa[4]) if prusa[4] else float("nan")
            print(f"{name}: file 1/{size_ratio:,.0f} of PrusaSlicer's (goal <= 1/300: "
                  f"{'met' if size_ratio >= 300 else 'NOT met'}), time {time_ratio:.2f} x "
                  f"PrusaSlicer's (goal < 1: {'met' if time_ratio < 1 else 'NOT met'}), "
                  f"blocks 1/{prusa[2] / blocks:,.0f}")
    print("published (METHODS §5): 36 KB versus 29 565 KB (1/821), 217 min versus 327 min (0.66 x)")
    print(f"files in {work}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
