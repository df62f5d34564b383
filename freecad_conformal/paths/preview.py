"""PNG preview of a plan's paths, coloured by sub-part (matplotlib, headless Agg backend).

matplotlib is imported inside the function, so planning works without it; the message
names the package when it is missing.
"""
from __future__ import annotations

from typing import IO

import numpy as np

from freecad_conformal.errors import PlanError

#: At most this many deposit polylines are drawn: beyond it a preview only gets slower and
#: darker; the paths are thinned evenly (every k-th layer's paths are kept whole).
MAX_DRAWN_PATHS = 20000


def render_png(assembly, target: IO[bytes], title: str = "", dpi: int = 110) -> None:
    """Draw deposit paths (one colour per sub-part) and travels (thin grey) into `target`."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        from matplotlib.figure import Figure
        from mpl_toolkits.mplot3d.art3d import Line3DCollection
    except ImportError as exc:
        raise PlanError("the PNG preview needs matplotlib (Debian: python3-matplotlib; "
                        "pip: matplotlib)") from exc
    paths = assembly.paths
    step = max(1, -(-len(paths) // MAX_DRAWN_PATHS))
    layers = sorted({(p.subpart, p.layer) for p in paths})
    keep = set(layers[::step])
    drawn = [p for p in paths if (p.subpart, p.layer) in keep]
    figure = Figure(figsize=(8, 7))
    axes = figure.add_subplot(projection="3d")
    colours = matplotlib.colormaps["tab10"]
    order = list(dict.fromkeys(p.subpart for p in paths))
    for rank, subpart in enumerate(order):
        lines = [p.points for p in drawn if p.subpart == subpart]
        # add_collection, not add_collection3d: matplotlib 3.10's add_collection3d raises
        # ValueError on lines of different lengths; a Line3DCollection projects itself.
        axes.add_collection(Line3DCollection(lines, colors=[colours(rank % 10)], linewidths=0.4,
                                             label=f"sub-part {subpart}"))
    if assembly.travels:
        axes.add_collection(Line3DCollection([t for t in assembly.travels if len(t) > 1][::step],
                                             colors=[(0.5, 0.5, 0.5, 0.35)], linewidths=0.2))
    every = np.concatenate([p.points for p in paths])
    low, high = every.min(axis=0), every.max(axis=0)
    centre, half = 0.5 * (low + high), 0.5 * float(np.max(high - low)) + 1.0
    axes.set_xlim(centre[0] - half, centre[0] + half)
    axes.set_ylim(centre[1] - half, centre[1] + half)
    axes.set_zlim(centre[2] - half, centre[2] + half)
    axes.set_xlabel("X mm")
    axes.set_ylabel("Y mm")
    axes.set_zlabel("Z mm")
    axes.set_title(title + (f" (every {step}th layer)" if step > 1 else ""))
    axes.legend(loc="upper left", fontsize="small")
    figure.savefig(target, format="png", dpi=dpi)
