"""Post-processor benchmark.

1. Post 1,000,000 points (a 5-axis cure spiral on a dome, table-table A/C, LinuxCNC) and
   print points per second, against a peer measured in the same run: formatting the same
   number of raw points as plain G1 lines (no kinematics), the floor of any post.
2. A 10-turn helix on the rotary mandrel: block count and bytes of our program versus a
   naive one-block-per-chord program at the same tolerance (the planner's 0.01 mm chords).
3. Verify (read, replay through forward kinematics, distance to the toolpath both ways)
   of the off-pivot LinuxCNC program from 1., against `rs274 -g` (LinuxCNC's own
   interpreter, which only reads and interprets) on the same file in the same run.

Run: .venv/bin/python benchmarks/post.py [--points N]
"""
from __future__ import annotations

import argparse
import math
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))   # run from anywhere

from freecad_conformal.post import samples  # noqa: E402
from freecad_conformal.post.dialects.base import number
from freecad_conformal.post.kinematics import inverse
from freecad_conformal.post.machine import load_machine
from freecad_conformal.post.program import machine_values, post_toolpath
from freecad_conformal.post.rs274 import rs274_path
from freecad_conformal.post.verify import verify_program


def naive_chords(toolpath, machine) -> str:
    """One G1 block per toolpath point: what a post without joint-space merging writes."""
    values = machine_values(machine, inverse(machine, toolpath.points, toolpath.axes))
    names = machine.joint_names
    return "".join("G1 " + " ".join(f"{n}{number(v)}" for n, v in zip(names, row)) + "\n"
                   for row in values.tolist())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=1_000_000)
    args = parser.parse_args()

    machine = load_machine("trunnion_ac")
    programs = {}
    for label, center in (("off the pivot", (15.0, -10.0, 5.0)), ("on the pivot", (0.0, 0.0, 0.0))):
        toolpath = samples.dome_spiral(args.points, turns=400, segments=1000, center=center)
        start = time.perf_counter()
        result = post_toolpath(toolpath, machine)
        ours = time.perf_counter() - start
        start = time.perf_counter()
        plain = "".join(f"G1 X{x:.4f} Y{y:.4f} Z{z:.4f}\n" for x, y, z in toolpath.points.tolist())
        peer = time.perf_counter() - start
        print(f"post {args.points:,} points (5-axis dome spiral {label}, trunnion_ac, linuxcnc): "
              f"{ours:.2f} s, {args.points / ours:,.0f} points/s, {len(result.values):,} blocks, "
              f"{len(result.text):,} bytes")
        print(f"  peer: formatting the raw points as 3-axis G1 lines: {peer:.2f} s, "
              f"{args.points / peer:,.0f} points/s ({len(plain):,} bytes); ours/peer time "
              f"{ours / peer:.2f}x")
        programs[label] = (toolpath, result)

    verify_against_rs274(machine, *programs["off the pivot"])

    mandrel = load_machine("rotary_mandrel")
    helix = samples.mandrel_helix(turns=10, chord_tolerance=0.01)
    posted = post_toolpath(helix, mandrel)
    naive = naive_chords(helix, mandrel)
    helix_blocks = sum(1 for line in posted.text.splitlines() if line.startswith(("G0", "G1")))
    naive_blocks = naive.count("\n")
    print(f"10-turn helix on rotary_mandrel ({len(helix.points):,} points at 0.01 mm chords): "
          f"{helix_blocks} blocks, {len(posted.text):,} bytes (whole program with header) vs "
          f"naive one block per chord: {naive_blocks:,} blocks, {len(naive):,} bytes; "
          f"{naive_blocks / helix_blocks:,.0f}x fewer blocks, {len(naive) / len(posted.text):,.0f}x smaller")


def verify_against_rs274(machine, toolpath, result, repeats: int = 3) -> None:
    """Time `verify` and `rs274 -g` on the same program (both read the whole file); the
    best of `repeats` runs each, so a busy shared machine hurts neither more."""
    blocks = len(result.values)
    ours = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        deviation = verify_program(result.text, machine, toolpath)
        ours = min(ours, time.perf_counter() - start)
    print(f"verify {blocks:,} blocks ({deviation.samples:,} samples): {ours:.2f} s, "
          f"{blocks / ours:,.0f} blocks/s; {deviation.position:.6f} mm, "
          f"{math.degrees(deviation.angle):.6f} deg (best of {repeats})")
    executable = rs274_path()
    if executable is None:
        print("  peer: rs274 is not installed (Debian package linuxcnc-uspace)")
        return
    peer = math.inf
    with tempfile.TemporaryDirectory() as folder:
        program = Path(folder) / "dome.ngc"
        program.write_text(result.text)
        for _ in range(repeats):
            start = time.perf_counter()
            subprocess.run([executable, "-g", str(program)], stdin=subprocess.DEVNULL,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
            peer = min(peer, time.perf_counter() - start)
    print(f"  peer: rs274 -g on the same program: {peer:.2f} s, {blocks / peer:,.0f} blocks/s "
          f"(best of {repeats}); ours/peer time {ours / peer:.2f}x")


if __name__ == "__main__":
    main()
