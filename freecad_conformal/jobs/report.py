"""The plan's text summary: sub-parts, directions, layers, path lengths, material, time."""
from __future__ import annotations

import numpy as np

from freecad_conformal.decomposition.planner import MIN_SAVING_FRACTION
from freecad_conformal.jobs.search import COARSE_EVERY, ordinal


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
    support = support_text(plan, any(sub.tilted_layers for sub in result.subparts),
                           result.hybrid is not None, result.support_volume,
                           bool(result.settings.get("support")))
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
    lines += _candidate_lines(result)
    lines += _hybrid_lines(result.hybrid)
    lines += [f"note: {note}" for note in plan.notes]
    return "\n".join(lines) + "\n"


def support_text(plan, tilted: bool, hybrid: bool, printed: float = 0.0,
                 asked: bool = False) -> str:
    """What the summary says of the overhang `plan` leaves: how much, and why it is left.
    `tilted`: some layers are 3-D; `hybrid`: the plan mills too; `printed`: the support
    material (mm³) the G-code prints under it; `asked`: support was on (`--support`)."""
    if plan.support_area <= 0:
        return "none"
    if printed > 0:
        return (f"{plan.support_area:.1f} mm2 of overhang beyond the allowed angle left "
                f"({overhang_reason(plan)}), printed on {printed / 1000:.3f} cm3 of support "
                "(part of the material above)")
    if tilted:
        # the decomposition measures its sub-parts as built in planar layers
        where = ("; the hybrid support line below has what the deposited layers need"
                 if hybrid else "")
        return (f"{plan.support_area:.1f} mm2 of overhang beyond the allowed angle as if "
                f"built in planar layers (the 3-D layers print some of it unsupported{where})")
    if asked:
        return (f"{plan.support_area:.1f} mm2 of overhang beyond the allowed angle left "
                f"({overhang_reason(plan)}); no support printed under it: the notes below "
                "say why (bridges laid from wall to wall, or columns left out)")
    # Without --support no support is made: say what the G-code does there, not only what
    # the part needs (a user added support to a file that had none, and could not say where).
    return (f"{plan.support_area:.1f} mm2 of overhang beyond the allowed angle left "
            f"({overhang_reason(plan)}; it needs support, which this G-code does not print: "
            "those areas are laid over air; --support prints it)")


def overhang_reason(plan) -> str | None:
    """Why `plan` leaves overhang (None when it leaves none): its own reason where it has
    one (`BuildPlan.support_reason`), else that no cut saves enough."""
    if plan.support_area <= 0:
        return None
    return plan.support_reason or (f"no cut found saves {MIN_SAVING_FRACTION:.0%} of a "
                                   "sub-part's overhang or more")


def _hybrid_lines(hybrid) -> list[str]:
    """Deposit and milling: times, switches, holes, support saved, the material check."""
    if hybrid is None:
        return []
    lines = ["", f"hybrid: deposit {format_duration(hybrid.deposit_s)}, milling "
             f"{format_duration(hybrid.milling_s)} ({', '.join(hybrid.mill_tools)}), travel "
             f"{format_duration(hybrid.travel_s)}, {hybrid.switches} switches "
             f"({format_duration(hybrid.switch_s)}; milling after every layer: "
             f"{hybrid.naive_switches})",
             f"stock: {hybrid.deposited_mm3:.0f} mm3 deposited for a part of "
             f"{hybrid.part_mm3:.0f} mm3: the mill removes {hybrid.stock_removed_mm3:.0f} mm3",
             f"support: {hybrid.support_hybrid_mm3:.1f} mm3; a planar build along the root "
             f"direction needs {hybrid.support_planar_mm3:.1f} mm3 "
             f"({100 * hybrid.support_saved:.0f} % saved)"]
    lines += [f"hole filled while depositing, cut afterwards: {hole}" for hole in hybrid.holes_filled]
    check = hybrid.check
    if check is not None:
        tolerance = min(check.by_offset) if check.by_offset else 0.0
        lines.append(f"material check (deposits less what the mill sweeps, at {check.points} "
                     f"points of the part's surface moved {tolerance:g} mm out and in): stock "
                     f"left at {check.uncut_points}, gouged or missing at {check.gouge_points}; "
                     f"stock stands up to {check.max_uncut:g} mm proud, gouges reach "
                     f"{check.max_gouge:g} mm in (sampled offsets)")
        if check.uncut_points and check.uncut_outside_corners is not None:
            lines.append(f"of the points with stock left, {check.uncut_outside_corners} lie "
                         "outside the concave corners the finishing cutter's radius cannot "
                         "reach into")
    return lines


#: Candidates the summary names besides the chosen plan (the report lists them all).
OTHERS_SHOWN = 2


def _candidate_lines(result) -> list[str]:
    """The chosen plan and the best others, each with what its figures come from (the
    chosen plan's paths, all its layers, or sampled layers: paths/cost.py), so a sampled
    estimate is not read as the chosen plan's own; a candidate that builds the same as one
    before it (a decomposition that made no cut, and the whole build along its root) is
    that one, and not shown twice."""
    builds = [row for row in result.candidates if row.get("same_build_as") is None]
    if len(builds) < 2:
        return []
    chosen = [row for row in builds if row["chosen"]]
    others = [row for row in builds if not row["chosen"]][:OTHERS_SHOWN]
    shown = chosen + others
    # As wide as the longest label (a refined direction's reads to three decimals).
    width = max(len(row["label"]) for row in shown)
    lines = ["", f"plans compared: {len(builds)}, least residual overhang first, then "
             f"the {result.objective} objective",
             f"   {'plan':<{width}} {'sub-parts':>9} {'overhang mm2':>12} {'cm3':>8} {'time':>8}"
             "  figures"]
    for mark, row in [("*", r) for r in chosen] + [(" ", r) for r in others]:
        lines.append(f" {mark} {row['label']:<{width}} {row['sub_parts']:>9} "
                     f"{row['residual_overhang_mm2']:>12.1f} {row['material_mm3'] / 1000:>8.3f} "
                     f"{format_duration(row['time_s']):>8}  {_figures_kind(row)}")
    kinds = {_figures_kind(row) for row in shown}
    lines.append("   figures: " + "; ".join(f"{kind} = {meaning}" for kind, meaning
                                            in FIGURES_MEANING.items() if kind in kinds))
    lines += [f"   {row['label']} is {row['mirror_of']} built from the other end (the same "
              "sections in reverse order): of the two, the one with the better sampled "
              "estimate was sliced, and this one keeps that estimate"
              for row in shown if row.get("mirror_of")]
    return lines


#: What a candidate row's time and material come from, as the summary names it.
FIGURES_MEANING = {"planned": "from the chosen plan's paths",
                   "sliced": "from all its layers, before paths",
                   "sampled": f"from every {ordinal(COARSE_EVERY)} layer, before paths",
                   "mirrored": "sampled, see below"}


def _figures_kind(row: dict) -> str:
    """Which of FIGURES_MEANING a report row's figures are."""
    if row.get("mirror_of"):
        return "mirrored"
    return {"plan": "planned", "layers": "sliced"}.get(row["estimate"], "sampled")


#: Version of the `plan --report` JSON (fields are only added, never renamed).
REPORT_FORMAT = "conformal.plan/1"


def report_data(result) -> dict:
    """The plan as JSON data (`plan --report`): totals, sub-parts, notes and every setting the
    plan used (settings/plan.py, with units; derived values marked)."""
    from freecad_conformal.settings.plan import PLAN_SETTINGS
    from freecad_conformal.settings.schema import as_json

    plan = result.plan
    built = {s.index: s for s in result.subparts}
    sub_parts = []
    for sub in plan.subparts:          # every sub-part, also those too thin for one layer
        summary = built.get(sub.index)
        sub_parts.append({
            "index": sub.index, "name": sub.name,
            "direction": [float(c) for c in sub.build_direction],
            "volume_mm3": float(sub.volume), "overhang_mm2": float(sub.overhang_area),
            "layers": summary.layers if summary else 0,
            "material_mm3": summary.material if summary else 0.0})
    return {
        "format": REPORT_FORMAT,
        "part": result.part,
        "machine": result.machine.name,
        "tool": result.tool_id,
        "material": result.material_name,
        "bead_width_mm": result.bead_width,
        "material_mm3": result.material_volume,
        "time_s": result.time_s,
        "residual_overhang_mm2": plan.support_area,
        "residual_overhang_reason": overhang_reason(plan),
        # the support printed under it (plan --support), part of material_mm3
        "support_mm3": result.support_volume,
        "single_direction_overhang_mm2": plan.support_area_single_direction,
        "build_order": list(plan.order),
        "sub_parts": sub_parts,
        "notes": list(plan.notes),
        # every plan compared, best first; empty when there was no choice (jobs/search.py)
        "objective": result.objective,
        "candidates": [dict(row) for row in result.candidates],
        # empty for options made in Python rather than from settings (settings/plan.py)
        "settings": _settings_used(result, as_json(PLAN_SETTINGS, result.settings))
        if result.settings else {},
        # deposition and milling (plan --process hybrid), None for an additive plan
        "hybrid": result.hybrid.to_json() if result.hybrid is not None else None,
    }


def _settings_used(result, settings: dict) -> dict:
    """The report's settings with what the plan resolved: each speed as printed (a derived
    one from the material), the machine's acceleration and the small-perimeter length."""
    from freecad_conformal.paths.assemble import SMALL_PERIMETER_LENGTH

    for role, speed in result.speeds.items():
        entry = settings.get(f"{role}_speed")
        if entry is not None:
            entry["used"] = speed
    settings["acceleration"] = {"value": result.machine.acceleration, "unit": "mm/s^2",
                                "derived": "the machine file"}
    settings["small_perimeter_length"] = {"value": SMALL_PERIMETER_LENGTH, "unit": "mm",
                                          "derived": "PrusaSlicer's rule: loops up to 2π·6.5 mm"}
    return settings
