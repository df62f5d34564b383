"""The DOE analysis as plain text for the command line (the GUI formats its own tables)."""
from __future__ import annotations

from freecad_conformal.process.doe.analysis import Analysis
from freecad_conformal.process.doe.design import Design


def _level_text(name: str, coded: float, value, design: Design | None) -> str:
    sign = {-1.0: "-", 0.0: "0", 1.0: "+"}.get(coded, f"{coded:+.3f}")
    if design is None:
        return f"{name}={sign}"
    factor = design.factor(name)
    shown = f"{value:.6g}" if isinstance(value, float) else str(value)
    unit = f" {factor.unit}" if factor.unit else ""
    label = f" {factor.label}" if factor.label else ""
    return f"{name}={sign} ({shown}{unit}{label})"


def effects_table(result: Analysis, design: Design | None = None) -> str:
    """Effects on the mean and ln s² with aliases, Lenth margins, models and the optimum."""
    lines = [f"data: {result.source}"]
    if result.defining_relation:
        lines.append("defining relation: I = " + " = ".join(
            ("-" if s < 0 else "") + w for w, s in result.defining_relation))
    ln_s2 = result.effects_ln_s2
    has_dispersion = ln_s2 is not None
    lines.append(f"{'effect':<8} {'aliases':<24} {'on mean':>10}" + (
        f" {'on ln s2':>10}" if has_dispersion else ""))
    for contrast in result.contrasts:
        label = contrast.label
        row = f"{label:<8} {contrast.alias_text():<24} {result.effects_mean[label]:>10.4f}"
        if ln_s2 is not None:
            row += f" {ln_s2[label]:>10.4f}"
        lines.append(row)
    margins = [("mean", result.lenth_mean), ("ln s2", result.lenth_ln_s2)]
    for name, lenth in margins:
        if lenth is None:
            continue
        lines.append(f"Lenth ({name}): PSE {lenth.pse:.4g}, ME {lenth.me:.4g}, "
                     f"SME {lenth.sme:.4g} (alpha {lenth.alpha:g})")
    lines.append("location model:   " + result.location.formula("y"))
    if result.dispersion is not None:
        lines.append("dispersion model: " + result.dispersion.formula("ln s2"))
    optimum = result.optimum
    levels = ", ".join(_level_text(name, optimum.coded[name], result.settings[name], design)
                       for name in result.names)
    lines.append(f"optimum ({optimum.goal}-the-better): {levels}")
    prediction = f"predicted mean {optimum.mean:.5g}"
    if result.predicted_real is not None:
        prediction += (f" = {optimum.mean:.5g} x {result.response_scale:g} = "
                       f"{result.predicted_real:.4g} {result.response_unit}").rstrip()
    if optimum.std is not None:
        prediction += f", predicted s {optimum.std:.3g}"
    lines.append(prediction)
    if optimum.free:
        lines.append(f"free factors (in no model, left low): {', '.join(optimum.free)}")
    lines += [f"note: {note}" for note in result.notes]
    return "\n".join(lines)
