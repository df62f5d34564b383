"""Time centroidal axis + decomposition per part, against a peer measured in the same run.

The peer is one batch of exact planar sections of the same part at the axis step (the
cheapest thing the axis must do); the ratio says how much the search and the splitting cost
on top. The published centroidal axis took 2–3 s per example on a 2.8 GHz Pentium 4; the
goal here is under 1 s per part for axis + decomposition.

"axis s" is the centroidal axis alone from +Z; "decompose s" is the whole plan: its own axis
(computed lazily, for the chosen root only), the cuts, the root trial of `auto` (run on
the second core) and the build order with the tool collision check. "support mm2" is what
the plan leaves, "single mm2" the best single direction's. The load average is printed with
the results: the machine is shared and the times move with it.

Run: .venv/bin/python benchmarks/decompose.py [--parts DIR] [--root auto|x,y,z]
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from freecad_conformal.errors import ConformalError  # noqa: E402
from freecad_conformal.geometry import samples  # noqa: E402
from freecad_conformal.geometry.centroidal_axis import centroidal_axis, default_step  # noqa: E402
from freecad_conformal.geometry.sections import planar_sections, extent_along  # noqa: E402
from freecad_conformal.geometry.solids import load_shape  # noqa: E402
from freecad_conformal.decomposition.decompose import decompose  # noqa: E402

REAL_PARTS = ("MODERN_Table_1.brep", "screw.step", "CrankArm.brep")


def timed(function):
    start = time.perf_counter()
    result = function()
    return result, time.perf_counter() - start


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    default = os.environ.get("CONFORMAL_PARTS", Path(__file__).resolve().parents[2] / "shared" / "parts")
    parser.add_argument("--parts", default=str(default))
    parser.add_argument("--root", default="auto",
                        help="root build direction passed to decompose (default auto, as the CLI)")
    args = parser.parse_args()
    if args.root != "auto":
        args.root = [float(c) for c in args.root.split(",")]
    parts = [(name, samples.SAMPLES[name]()) for name in ("l_block", "t_block", "inclined_rod", "hinge")]
    folder = Path(args.parts)
    for name in REAL_PARTS:
        if (folder / name).is_file():
            parts.append((name, load_shape(folder / name)))
        else:
            print(f"skipping {name}: not in {folder}")
    print("load average (1, 5, 15 min): " + ", ".join(f"{x:.2f}" for x in os.getloadavg()))
    print(f"{'part':<22}{'sections s':>11}{'axis s':>9}{'decompose s':>13}{'ratio':>8}"
          f"{'sub-parts':>11}{'support mm2':>13}{'single mm2':>13}")
    for name, shape in parts:
        import numpy as np

        up = np.array([0.0, 0.0, 1.0])
        low, high = extent_along(shape, up)
        step = default_step(shape, up, (low, high))
        _, peer = timed(lambda: planar_sections(shape, heights=list(np.arange(low + step / 2, high, step))))
        _, axis_time = timed(lambda: centroidal_axis(shape))
        try:
            plan, total = timed(lambda: decompose(shape, root_direction=args.root))
        except ConformalError as exc:
            print(f"{name:<22}{peer:>11.3f}{axis_time:>9.3f}  error: {exc}")
            continue
        print(f"{name:<22}{peer:>11.3f}{axis_time:>9.3f}{total:>13.3f}{total / peer:>8.1f}"
              f"{len(plan.subparts):>11}{plan.support_area:>13.1f}"
              f"{plan.support_area_single_direction:>13.1f}")
    print("load average (1, 5, 15 min): " + ", ".join(f"{x:.2f}" for x in os.getloadavg()))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
