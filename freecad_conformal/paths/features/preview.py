"""A preview PNG of a feature program: cures coloured by tool, travels thin and grey, the
face faintly underneath, equal scales on all three axes (matplotlib Agg, imported late)."""
from __future__ import annotations

import os

import numpy as np

from freecad_conformal.errors import PlanError
from freecad_conformal.fileio import atomic_write
from freecad_conformal.toolpath import KINDS, Toolpath

TOOL_COLOURS = ("tab:red", "tab:blue", "tab:green", "tab:purple", "tab:orange")
#: At most this many surface points are drawn (a hint of the face, not a rendering).
MAX_SURFACE_POINTS = 4000


def write_preview(tp: Toolpath, path: str | os.PathLike, title: str,
                  surface: np.ndarray | None = None, dpi: int = 110) -> None:
    """Write the preview of `tp` to `path` (atomically)."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        from matplotlib.figure import Figure
    except ImportError as exc:
        raise PlanError("the feature preview needs matplotlib (Debian: apt-get install "
                        "python3-matplotlib; pip: pip install matplotlib)") from exc
    figure = Figure(figsize=(7.0, 6.0))
    axes = figure.add_subplot(projection="3d")
    starts = tp.segment_starts
    cure, travel = KINDS.index("cure"), KINDS.index("travel")
    tools = sorted(set(int(t) for t in tp.tool))
    colour = {t: TOOL_COLOURS[k % len(TOOL_COLOURS)] for k, t in enumerate(tools)}
    names = dict(item.split(" ", 1) for item in tp.metadata.get("tools", "").split(", ") if " " in item)
    if surface is not None and len(surface):
        step = max(len(surface) // MAX_SURFACE_POINTS, 1)
        s = surface[::step]
        axes.scatter(s[:, 0], s[:, 1], s[:, 2], s=1, c="0.8", alpha=0.4, depthshade=False)
    cured = tp.points[np.isin(np.repeat(np.arange(tp.segment_count), np.diff(starts)),
                              np.flatnonzero(tp.kind == cure))]
    box = cured if len(cured) else tp.points
    low, high = box.min(axis=0), box.max(axis=0)
    middle, half = (low + high) / 2, max(float(np.max(high - low)) / 2, 1.0) * 1.1
    labelled: set[int] = set()
    for seg in range(tp.segment_count):
        first = max(starts[seg] - 1, 0) if tp.kind[seg] == travel else starts[seg]
        xyz = tp.points[first:starts[seg + 1]]
        if tp.kind[seg] == cure:
            tool = int(tp.tool[seg])
            label = None if tool in labelled else f"T{tool} {names.get(f'T{tool}', '')}".strip()
            labelled.add(tool)
            axes.plot(xyz[:, 0], xyz[:, 1], xyz[:, 2], color=colour[tool], linewidth=1.2,
                      label=label)
        elif tp.kind[seg] == travel:
            # 3D axes do not clip: travels home (20 mm out) are cut at the box
            shown = np.where(np.all(np.abs(xyz - middle) <= half, axis=1)[:, None], xyz, np.nan)
            axes.plot(shown[:, 0], shown[:, 1], shown[:, 2], color="0.6", linewidth=0.3)
    axes.set_xlim(middle[0] - half, middle[0] + half)
    axes.set_ylim(middle[1] - half, middle[1] + half)
    axes.set_zlim(middle[2] - half, middle[2] + half)
    axes.set_box_aspect((1, 1, 1))
    axes.set_xlabel("X mm")
    axes.set_ylabel("Y mm")
    axes.set_zlabel("Z mm")
    summary = tp.summary()
    axes.set_title(f"{title}\n{summary.length_by_kind['cure']:.0f} mm cured, "
                   f"{summary.energy:.2f} J, {summary.time_s / 60:.1f} min", fontsize=10)
    if labelled:
        axes.legend(loc="upper left", fontsize=8)
    figure.tight_layout()
    with atomic_write(path, "wb") as handle:
        figure.savefig(handle, format="png", dpi=dpi)
