"""What cooling-aware interleaving could save, at most, on each part's chosen plan.

Issue 16 asks to build layers of other ready sub-parts while a short layer cools, when that
beats slowing it down. Interleaving goes round levels of different sub-parts, turning the
table between each and the next: a round through m levels makes m moves, so every level
interleaved costs at least one move between sub-parts, and only what cooling added to it
beyond that move can be won. For each part this prints the plan's time, the seconds
cooling added (`PlanCost.cooling`, the cost model's own reading, within 10 % of the full
plan's), the plan's shortest move between sub-parts, and the bound: the sum over levels of
what cooling added beyond one such move. A plan of one sub-part (or of sub-parts all built
together, level by level) has nothing to interleave with. The plan does interleave where
its own estimate says it pays (`paths/alternate.py`, `--alternate`): this bound says how
much it could win at most at the default settings, before any path is planned.

Run: .venv/bin/python benchmarks/cooling_bound.py [parts...]   (default: the samples, the
parts in ../shared/parts and the own parts)
"""
from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))   # run from anywhere
sys.path.insert(0, str(Path(__file__).resolve().parent))

from own_parts import OWN_PARTS  # noqa: E402
from plan_speed import PARTS_DIR  # noqa: E402


def bound(name: str) -> tuple[str, float, float, float | None, float, int]:
    """(label, plan seconds, cooling seconds, shortest move s or None, bound s, sub-parts)."""
    from freecad_conformal.geometry.samples import load_part
    from freecad_conformal.jobs.options import plan_options
    from freecad_conformal.jobs.plan import check_options, choose_plan
    from freecad_conformal.layers.plan import plan_layers
    from freecad_conformal.paths.cost import Motion, plan_cost

    shape, label = (OWN_PARTS[name](), name) if name in OWN_PARTS else load_part(name)
    options = plan_options({})
    checked = check_options(shape, options, None)
    choice = choose_plan(shape, options, checked)
    layers = choice.layers or {sub.index: plan_layers(sub, options.layers)
                               for sub in choice.plan.subparts}
    _, _, _, path_settings, machine = checked
    cost = plan_cost(choice.plan, layers, path_settings, Motion.of(machine, options.jerk))
    shortest = min(cost.moves) if cost.moves else None
    gain = 0.0 if shortest is None else sum(max(0.0, slow - shortest) for slow in cost.cooling)
    return label, cost.seconds, sum(cost.cooling), shortest, gain, len(choice.plan.subparts)


def main(names: list[str]) -> int:
    from freecad_conformal.geometry.samples import SAMPLES

    parts = names or [str(p) for p in sorted(PARTS_DIR.glob("*"))
                      if p.suffix.lower() in (".step", ".brep")] + list(SAMPLES) + list(OWN_PARTS)
    print(f"{'part':18} {'sub-parts':>9} {'plan s':>8} {'cooling s':>9} {'share':>6} "
          f"{'move s':>7} {'bound s':>8}")
    for name in parts:
        label, seconds, cooling, shortest, gain, count = bound(name)
        move = "-" if shortest is None else f"{shortest:.1f}"
        print(f"{label:18} {count:9d} {seconds:8.0f} {cooling:9.1f} {cooling / seconds:6.1%} "
              f"{move:>7} {gain:8.1f}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
