"""Half-normal plots of the effects as a PNG (matplotlib, headless Agg backend).

matplotlib is imported inside the function: the rest of the DOE works without it, and the
Agg backend needs no display (CI, command line, FreeCAD without GUI)."""
from __future__ import annotations

import os

from freecad_conformal.errors import ProcessError
from freecad_conformal.fileio import atomic_write
from freecad_conformal.process.doe.analysis import Analysis, HalfNormal
from freecad_conformal.process.doe.stats import Lenth


def half_normal_panel(axes, points: HalfNormal, margins: Lenth, chosen: set[str], title: str) -> None:
    colours = ["tab:red" if label in chosen else "tab:blue" for label in points.labels]
    axes.scatter(points.quantiles, points.magnitudes, c=colours, zorder=3)
    for label, x, y in zip(points.labels, points.quantiles, points.magnitudes):
        axes.annotate(label, (x, y), textcoords="offset points", xytext=(5, 3), fontsize=9)
    axes.axhline(margins.me, color="tab:orange", linestyle="--", linewidth=1,
                 label=f"Lenth ME {margins.me:.3g}")
    axes.axhline(margins.sme, color="tab:gray", linestyle=":", linewidth=1,
                 label=f"Lenth SME {margins.sme:.3g}")
    # both margins stay inside the axes (SME is often far above every effect of a small
    # design: the plot is then mostly empty, but the comparison is what it is drawn for)
    axes.set_ylim(0.0, 1.15 * max(max(points.magnitudes), margins.me, margins.sme))
    axes.set_xlabel("half-normal quantile")
    axes.set_ylabel("|effect|")
    axes.set_title(title)
    axes.grid(True, alpha=0.3)
    axes.legend(fontsize=8, loc="upper left")


def write_half_normal_png(result: Analysis, path: str | os.PathLike, dpi: int = 120) -> None:
    """One panel for the mean, one for ln s² when known; model terms drawn in red."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        from matplotlib.figure import Figure
    except ImportError as exc:
        raise ProcessError("the DOE plot needs matplotlib (Debian: apt-get install "
                           "python3-matplotlib; pip: pip install matplotlib)") from exc
    panels = 2 if result.effects_ln_s2 is not None else 1
    figure = Figure(figsize=(5.5 * panels, 4.5))
    axes = figure.subplots(1, panels, squeeze=False)[0]
    assert result.lenth_mean is not None, "an analysis always has the mean's margins"
    half_normal_panel(axes[0], result.half_normal("mean"), result.lenth_mean,
                      set(result.location.coefficients), "effects on the mean")
    if panels == 2 and result.lenth_ln_s2 is not None:
        dispersion = set(result.dispersion.coefficients) if result.dispersion else set()
        half_normal_panel(axes[1], result.half_normal("ln_s2"), result.lenth_ln_s2,
                          dispersion, "effects on ln s²")
    figure.tight_layout()
    with atomic_write(path, "wb") as handle:
        figure.savefig(handle, format="png", dpi=dpi)
