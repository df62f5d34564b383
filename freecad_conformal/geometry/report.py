"""Section reports for the command line and the demo: a table and the documented JSON."""
from __future__ import annotations

import json
import os
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from freecad_conformal.errors import GeometryError
from freecad_conformal.fileio import write_text_atomic
from freecad_conformal.progress import Progress

#: Default layer spacing (mm) when neither spacing nor heights are given.
DEFAULT_REPORT_LAYER = 1.0


@dataclass
class SectionReport:
    source: str
    stack: object  # SectionStack or CylindricalStack
    volume: float | None

    def rows(self) -> list[tuple]:
        rows = []
        for index, layer in enumerate(self.stack.layers):
            level = getattr(layer, "height", None)
            if level is None:
                level = layer.radius
            rows.append((index + 1, level, len(layer.loops), layer.area, layer.centroid))
        return rows

    def table(self) -> str:
        cylindrical = self.stack.to_dict(with_points=False)["kind"] == "cylindrical"
        level_name = "radius" if cylindrical else "height"
        lines = [f"{self.source}: {len(self.stack.layers)} "
                 f"{'cylindrical' if cylindrical else 'planar'} sections, direction "
                 + ",".join(f"{c:g}" for c in self.stack.to_dict(False)["direction"]),
                 f"{'layer':>5} {level_name:>10} {'loops':>5} {'area mm2':>14}   centroid (x, y, z) mm"]
        for index, level, loops, area, centroid in self.rows():
            where = ("-" if not np.all(np.isfinite(centroid))
                     else ", ".join(f"{c:10.4f}" for c in centroid))
            lines.append(f"{index:5d} {level:10.4f} {loops:5d} {area:14.6f}   {where}")
        if self.volume is not None and not cylindrical:
            lines.append(f"solid volume {self.volume:.4f} mm3")
        for height, how in sorted(getattr(self.stack, "repairs", {}).items()):
            lines.append(f"note: the section at {height:.4f} came back empty at first; {how}")
        return "\n".join(lines) + "\n"

    def to_dict(self) -> dict:
        data = {"source": self.source, **self.stack.to_dict(with_points=True)}
        if self.volume is not None:
            data["solid_volume"] = self.volume
        return data


def section_report(part, *, layer: float | None = None, heights: Sequence[float] | None = None,
                   radii: Sequence[float] | None = None,
                   direction: Sequence[float] = (0.0, 0.0, 1.0),
                   axis_point: Sequence[float] = (0.0, 0.0, 0.0), chord: float | None = None,
                   workers: int = 1, json_path: str | os.PathLike | None = None,
                   show_progress: bool = False) -> SectionReport:
    """Sections of a part file (or shape) with an optional JSON report written atomically."""
    from freecad_conformal.geometry.cylindrical import cylindrical_sections
    from freecad_conformal.geometry.sections import planar_sections, uniform_heights
    from freecad_conformal.geometry.solids import load_shape
    from freecad_conformal.tolerances import DEFAULT_CHORD_TOLERANCE

    shape = load_shape(part) if isinstance(part, (str, os.PathLike)) else part
    source = os.path.basename(str(part)) if isinstance(part, (str, os.PathLike)) else "shape"
    chord = DEFAULT_CHORD_TOLERANCE if chord is None else chord
    if radii is not None:
        bar = Progress(len(radii), "sections") if show_progress else None
        stack = cylindrical_sections(shape, radii, axis_point, direction, chord_tolerance=chord,
                                     progress=_updater(bar))
    else:
        if heights is None:
            heights = uniform_heights(shape, direction, DEFAULT_REPORT_LAYER if layer is None else layer)
        if not heights:
            raise GeometryError("no section heights: the part has no extent along the direction")
        bar = Progress(len(heights), "sections") if show_progress else None
        stack = planar_sections(shape, direction, heights=heights, chord_tolerance=chord,
                                progress=_updater(bar), workers=workers)
    if bar is not None:
        bar.close()
    report = SectionReport(source=source, stack=stack, volume=float(shape.Volume))
    if json_path is not None:
        write_text_atomic(json_path, json.dumps(report.to_dict(), indent=1))
    return report


def _updater(bar: Progress | None):
    if bar is None:
        return None

    def update(done: int, total: int) -> None:
        bar.update(done - bar.done)

    return update
