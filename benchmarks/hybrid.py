"""Hybrid deposition + milling benchmark (issue: hybrid plans, METHODS section 6).

For each part (built-in samples made for it: the 45° branch on a block, a block with a
hole across the build, a nozzle with a 0.5 mm hole, a domed cylinder; or files given; "+V-bit"
and "+ball" rows list that tool after the end mill), plan it with
`--process hybrid` and print, against the peers measured in the same run:
- switches between deposition and milling, against a plan that mills after every layer
  (the naive plan: same layers, same passes);
- support volume: ours (under the layers as deposited: a surface point overhangs by the
  normal of the layer it lies in, so 3-D layers that follow a lean need none there) against
  a planar 2.5-D build of the same part along +Z, measured the same way (every point
  overhanging more than 45° supported down to the part or the platform,
  `geometry/support.layered_support_volume`);
- the material check: points of the part's surface moved 0.05 mm (then 0.1 … 5 mm) out
  and in, classified against deposits less later sweeps: how many show stock left or a
  gouge at the tolerance, and the largest offset at which any does; "off corners": the
  points with stock left outside the concave corners a cutter of the finishing radius
  cannot reach into (`geometry/stock.corner_zones`);
- times: deposit, milling, travel and switches (estimated), and the planner's wall time.

Run: .venv/bin/python benchmarks/hybrid.py [PART ...] [--layer-height 0.5]
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))   # run from anywhere

from freecad_conformal.geometry import samples  # noqa: E402
from freecad_conformal.geometry.samples import load_part  # noqa: E402
from freecad_conformal.jobs.job import plan_job  # noqa: E402
from freecad_conformal.jobs.options import plan_options  # noqa: E402

#: The V-bit after the end mill runs pencil passes along sharp concave edges.
VBIT = {"mill_tool": "endmill_6mm,vbit_30deg_6mm"}

PARTS = {"branch45": {}, "branch45 +V-bit": VBIT, "branch45 planar": {"tilt": False},
         "branch55": {}, "branch55 +V-bit": VBIT, "t_block": {},
         "cross_hole_block": {}, "nozzle": {"mill_tool": "endmill_6mm,drill_0p5"},
         "domed_cylinder": {}, "domed_cylinder +ball": {"mill_tool": "endmill_6mm,ball_endmill_6mm"}}

#: Parts made here rather than by name: the branch leaning 55° (past the 45° rule).
MADE = {"branch55": lambda: samples.branch45(lean_deg=55.0)}


def run(name: str, extra: dict, layer: float) -> dict:
    base = name.split()[0]
    shape = MADE[base]() if base in MADE else load_part(base)[0]
    label = name
    values = {"process": "hybrid", "tool": "laser_powder", "machine": "hybrid_ac",
              "layer_height": layer, **extra}
    start = time.perf_counter()
    result = plan_job(shape, plan_options(values), part=label)
    seconds = time.perf_counter() - start
    h = result.hybrid
    check = h.check
    return {"part": label, "wall_s": seconds, "layers": sum(s.layers for s in result.subparts),
            "tilted": sum(s.tilted_layers for s in result.subparts),
            "sub_parts": len(result.subparts), "switches": h.switches, "naive": h.naive_switches,
            "support_planar": h.support_planar_mm3, "support_ours": h.support_hybrid_mm3,
            "saved": h.support_saved, "points": check.points,
            "uncut": check.uncut_points, "gouged": check.gouge_points,
            "uncut_outside": check.uncut_outside_corners,
            "max_uncut": check.max_uncut, "max_gouge": check.max_gouge,
            "deposit_s": h.deposit_s, "milling_s": h.milling_s, "travel_s": h.travel_s,
            "switch_s": h.switch_s, "sessions": h.sessions}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("parts", nargs="*", help="part files or sample names (default: PARTS)")
    parser.add_argument("--layer-height", type=float, default=0.5)
    args = parser.parse_args(argv)
    names = args.parts or list(PARTS)
    rows = [run(name, PARTS.get(name, {}), args.layer_height) for name in names]
    print(f"{'part':<18} {'sub':>3} {'layers':>6} {'3-D':>4} {'switches':>8} {'naive':>6} "
          f"{'fewer':>6} {'support planar':>14} {'ours':>6} {'saved':>6} {'points':>6} "
          f"{'stock>0.05':>10} {'off corners':>11} {'max mm':>6} {'gouge>0.05':>10} {'max mm':>6} "
          f"{'plan s':>7}")
    for r in rows:
        fewer = r["naive"] / max(r["switches"], 1)
        saved = f"{100 * r['saved']:.0f} %" if r["support_planar"] > 0 else "n/a"
        print(f"{r['part']:<18} {r['sub_parts']:>3} {r['layers']:>6} {r['tilted']:>4} "
              f"{r['switches']:>8} {r['naive']:>6} {fewer:>5.1f}x {r['support_planar']:>14.1f} "
              f"{r['support_ours']:>6.1f} {saved:>6} {r['points']:>6} {r['uncut']:>10} "
              f"{r['uncut_outside']:>11} {r['max_uncut']:>6g} {r['gouged']:>10} "
              f"{r['max_gouge']:>6g} {r['wall_s']:>7.1f}")
    print()
    print(f"{'part':<18} {'deposit s':>9} {'milling s':>9} {'travel s':>9} {'switch s':>9}  "
          "milling sessions (reason: count)")
    for r in rows:
        reasons: dict[str, int] = {}
        for s in r["sessions"]:
            reasons[s["reason"]] = reasons.get(s["reason"], 0) + 1
        print(f"{r['part']:<18} {r['deposit_s']:>9.0f} {r['milling_s']:>9.0f} "
              f"{r['travel_s']:>9.0f} {r['switch_s']:>9.0f}  "
              + ", ".join(f"{k}: {v}" for k, v in reasons.items()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
