"""The plan's text summary: sub-parts, directions, layers, path lengths, material, time."""
from __future__ import annotations

import numpy as np


def format_duration(seconds: float) -> str:
    """h:mm:ss"""
    whole = int(round(seconds))
    return f"{whole // 3600}:{whole // 60 % 60:02d}:{whole % 60:02d}"


def _direction(vector: np.ndarray) -> str:
    return "(" + ", ".join(f"{c:+.3f}" for c in vector) + ")"


def summary_text(result) -> str:
    """A table per sub-part and the totals (material: bead cross-section × length)."""
    lines = [
        f"part: {result.part}",
        f"machine: {result.machine.name}; tool: {result.tool_id} ({result.material_name}), "
        f"bead {result.bead_width:g} mm",
        "",
        f"{'sub-part':<22} {'direction':<26} {'layers':>6} {'thick. mm':>13} {'tilted':>6} "
        f"{'path m':>8} {'cm3':>8}",
    ]
    for sub in result.subparts:
        lines.append(f"{sub.index:>2} {sub.name[:19]:<19} {_direction(sub.direction):<26} "
                     f"{sub.layers:>6} {sub.thickness_min:>6.3f}-{sub.thickness_max:<6.3f} "
                     f"{sub.tilted_layers:>6} {sub.deposit_length / 1000:>8.2f} {sub.material / 1000:>8.3f}")
    plan = result.plan
    support = ("none" if plan.support_area <= 0 else f"{plan.support_area:.1f} mm2 of overhang "
               "beyond the allowed angle left (no cut found removes it: it needs support)")
    lines += [
        "",
        f"build order: {' -> '.join(str(i) for i in plan.order)}",
        f"layers: {sum(s.layers for s in result.subparts)}; deposit path {result.deposit_length / 1000:.2f} m, "
        f"travel {result.travel_length / 1000:.2f} m",
        f"material: {result.material_volume / 1000:.3f} cm3 (bead cross-section x path length)",
        f"estimated time: {format_duration(result.time_s)} ({result.time_s:.0f} s; trapezoidal "
        f"acceleration {result.machine.acceleration:g} mm/s2, jerk-limited corners)",
        f"support: {support}"
        + (f" (a single direction would need {plan.support_area_single_direction:.1f} mm2)"
           if plan.support_area_single_direction > 0 else ""),
        f"safe moves between sub-parts checked against built material: {result.assembly.moves_checked}",
        f"G-code: {len(result.post.values)} blocks",
    ]
    lines += [f"note: {note}" for note in plan.notes]
    return "\n".join(lines) + "\n"
