"""Build plans out: the text table, the JSON file and one STEP file per sub-part."""
from __future__ import annotations

import json
import math
import os
import tempfile
from pathlib import Path

from freecad_conformal.fileio import make_output_folder, write_text_atomic
from freecad_conformal.decomposition.subparts import BuildPlan

def _direction(vector) -> str:
    return "(" + ", ".join(f"{float(c):+.3f}" for c in vector) + ")"


def plan_table(plan: BuildPlan) -> str:
    """The tree as text: sub-part, parent, volume, direction, order, overhang."""
    rank = {index: position + 1 for position, index in enumerate(plan.order)}
    lines = [f"{'sub-part':<9}{'parent':<8}{'order':>6}{'volume mm3':>14}  "
             f"{'direction':<26}{'rotation':>22}{'overhang mm2':>14}  rule"]
    for sub in plan.subparts:
        parent = plan.subparts[sub.parent].name if sub.parent is not None else "-"
        rotation = f"{math.degrees(sub.rotation_angle):.1f} about {_direction(sub.rotation_axis)}"
        lines.append(f"{sub.name:<9}{parent:<8}{rank[sub.index]:>6}{sub.volume:>14.3f}  "
                     f"{_direction(sub.build_direction):<26}{rotation:>22}"
                     f"{sub.overhang_area:>14.3f}  {sub.rule}")
    lines.append(f"support area: {plan.support_area:.3f} mm2 with the plan, "
                 f"{plan.support_area_single_direction:.3f} mm2 in the best single direction "
                 f"{_direction(plan.single_direction)}; saved {plan.support_area_saved:.3f} mm2")
    lines.extend(f"note: {note}" for note in plan.notes)
    return "\n".join(lines) + "\n"


def write_plan(plan: BuildPlan, json_path: str | os.PathLike | None = None,
               step_dir: str | os.PathLike | None = None) -> list[Path]:
    """Write the JSON plan and/or one STEP per sub-part (`P1.step`, ...); returns the paths."""
    written: list[Path] = []
    if json_path:
        path = Path(json_path)
        write_text_atomic(path, json.dumps(plan.to_dict(), indent=1) + "\n")
        written.append(path)
    if step_dir:
        folder = make_output_folder(step_dir)
        for sub in plan.subparts:
            target = folder / f"{sub.name}.step"
            # OCC writes STEP by file name only: write beside the target, then rename.
            handle, temp = tempfile.mkstemp(suffix=".step", dir=folder)
            os.close(handle)
            try:
                sub.shape.exportStep(temp)
                os.replace(temp, target)
            finally:
                if os.path.exists(temp):
                    os.unlink(temp)
            written.append(target)
    return written
