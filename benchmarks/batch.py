"""Batch throughput: parts per minute with 1 and 2 local workers, and the streamer's speed.

1. Twenty generated parts (L-blocks, T-blocks and jacks of varied sizes, written as BREP
   and STEP) go through `run_batch` with 1 worker, then with 2, in the same run: parts per
   minute for each and the ratio (the speed-up a second core gives; the ideal is the number
   of free cores, and process start-up and the longest part keep it below that).
2. The streamer's lines per second into OctoPrint's virtual printer against Printrun's
   printcore, measured in the same run by benchmarks/stream.py's own functions.

    .venv/bin/python benchmarks/batch.py [--parts 20] [--layer 1.0] [--lines 3000]
"""
from __future__ import annotations

import argparse
import importlib.util
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from freecad_conformal.jobs.batch.run import run_batch  # noqa: E402
from freecad_conformal.geometry import samples  # noqa: E402
from freecad_conformal.jobs.plan import PlanOptions  # noqa: E402
from freecad_conformal.layers.model import LayerSettings  # noqa: E402


def generate_parts(folder: Path, count: int) -> list[str]:
    """`count` parts of three families, each a little larger than the last of its kind."""
    files = []
    for k in range(count):
        scale = 1.0 + 0.04 * k
        family = k % 3
        if family == 0:
            shape, name = samples.l_block(height=30.0 * scale, arm=20.0 * scale), f"l_block_{k:02d}.brep"
        elif family == 1:
            shape, name = samples.t_block(height=30.0 * scale, arm=18.0 * scale), f"t_block_{k:02d}.step"
        else:
            shape, name = samples.jack(cube=10.0 * scale, arm_length=18.0 * scale), f"jack_{k:02d}.brep"
        path = folder / name
        if path.suffix == ".step":
            shape.exportStep(str(path))
        else:
            shape.exportBrep(str(path))
        files.append(str(path))
    return files


def time_batch(files: list[str], options, workers: int, out: Path) -> tuple[float, float]:
    """(wall seconds for the whole batch, worker start-up included as a user waits for it;
    CPU seconds the workers used). Both, so a machine busy with other work shows up as
    CPU time well below workers x wall time rather than as a mysterious ratio."""
    before = os.times()
    started = time.perf_counter()
    result = run_batch(files, options, out, workers=workers)
    elapsed = time.perf_counter() - started
    after = os.times()
    if result.failed:
        failures = [f"{row['part']}: {row['error']}" for row in result.rows if row["status"] != "ok"]
        raise RuntimeError("benchmark parts failed:\n" + "\n".join(failures))
    cpu = (after.children_user + after.children_system) - (before.children_user + before.children_system)
    return elapsed, cpu


def stream_benchmark():
    """benchmarks/stream.py as a module (benchmarks/ is not a package)."""
    spec = importlib.util.spec_from_file_location("stream_benchmark", HERE / "stream.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--parts", type=int, default=20)
    parser.add_argument("--layer", type=float, default=1.0, help="layer height in mm (default 1)")
    parser.add_argument("--lines", type=int, default=3000, help="streamed lines (default 3000)")
    parser.add_argument("--repeats", type=int, default=3, help="stream repeats (default 3)")
    args = parser.parse_args()
    # Beads as wide as the layers are tall: a layer may be no taller (jobs/plan.check_options).
    options = PlanOptions(layers=LayerSettings(thickness=args.layer),
                          bead_width=max(args.layer, 0.4))
    with tempfile.TemporaryDirectory(prefix="conformal-batch-bench-") as folder:
        root = Path(folder)
        (root / "parts").mkdir()
        files = generate_parts(root / "parts", args.parts)
        load = os.getloadavg()[0]
        timings = {workers: time_batch(files, options, workers, root / f"out{workers}")
                   for workers in (1, 2)}
    rate = {workers: 60.0 * args.parts / wall for workers, (wall, _cpu) in timings.items()}
    print(f"batch: {args.parts} generated parts, layer {args.layer:g} mm, {os.cpu_count()} CPUs, "
          f"load average {load:.1f} before the runs")
    for workers, (wall, cpu) in timings.items():
        print(f"  {workers} worker{'s' if workers > 1 else ' '}: {wall:6.1f} s {rate[workers]:6.1f} "
              f"parts/min  (workers' CPU {cpu:5.1f} s = {cpu / wall:4.2f} cores busy)")
    print(f"  ratio 2 workers / 1 worker: {rate[2] / rate[1]:.2f}")

    stream = stream_benchmark()
    program = stream.make_program(args.lines)
    ours = statistics.median(stream.time_ours(program) for _ in range(args.repeats))
    peer = statistics.median(stream.time_printrun(program) for _ in range(args.repeats))
    print(f"stream: {args.lines} lines into OctoPrint's virtual printer, median of {args.repeats}")
    print(f"  conformal stream  : {args.lines / ours:8.0f} lines/s")
    print(f"  Printrun printcore: {args.lines / peer:8.0f} lines/s")
    print(f"  ratio ours/Printrun: {peer / ours:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
