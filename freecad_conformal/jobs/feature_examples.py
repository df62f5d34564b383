"""The published test cases of METHODS section 1, planned with the calibrated tools and set
against the published figures: `python -m freecad_conformal.jobs.feature_examples -o DIR`
writes each part (.brep), toolpath (.npz), preview (.png) and a table (examples.md).

The calibration points of the shipped tools are themselves published figures (the rods'
0.75 mm/s for ∅ 1.2 mm, the cup's 0.4 mm/s for a 2.3 mm wall): those rows check that the
planners carry the calibration through to the program, not an independent prediction.
"""
from __future__ import annotations

import argparse
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from freecad_conformal.fileio import write_text_atomic
from freecad_conformal.paths.features import feeds, rods
from freecad_conformal.process.library import ToolLibrary
from freecad_conformal.toolpath import KINDS, Toolpath

VMAX = 3.556  # mm/s, METHODS section 1


@dataclass
class Example:
    name: str
    quantity: str
    published: str
    ours: str
    toolpath: Toolpath | None = None


def _face(shape, kind: str, pick=None):
    from freecad_conformal.geometry.faces import face_kind
    faces = [f for f in shape.Faces if face_kind(f) == kind]
    return min(faces, key=pick) if pick else faces[0]


def _cure_feeds(tp: Toolpath) -> list[float]:
    return sorted({round(float(f) / 60.0, 3) for f in tp.feed[tp.kind == KINDS.index("cure")]})


def spiral(library: ToolLibrary, App, Part, out: Path) -> list[Example]:
    """Flat spiral, small tool: rings of a 10 mm disc (contours), 0.3 mm lines."""
    from freecad_conformal.jobs.feature import plan_feature
    plate = Part.makeBox(30, 30, 2, App.Vector(-15, -15, -2))
    top = _face(plate, "plane", pick=lambda f: -f.CenterOfMass.z)
    circle = [f"L{5 * math.cos(t):.4f} {5 * math.sin(t):.4f}"
              for t in np.linspace(0, 2 * math.pi, 73)[1:]]
    (out / "disc.svg").write_text(" ".join(["M5 0"] + circle + ["Z"]))
    tp = plan_feature(top, "pattern", {"svg": str(out / "disc.svg"), "width": 0.3, "height": 0.3,
                                       "layer": 0.3}, "flat spiral", part=plate)
    small = library.get("uv_small")
    fit = feeds.line_fit(small)
    power = feeds.material_settings(small)[1].power or 0.495
    widths = {v: fit.width(power, v) for v in (1.3, 1.8)}
    return [Example("flat spiral, small tool", "feed for 0.3 mm lines",
                    "1.3 mm/s good (inner), 1.8 mm/s defects (outer)",
                    f"{_cure_feeds(tp)[0]:.3g} mm/s; at 0.495 W the fit gives "
                    f"{widths[1.3]:.3f} mm at 1.3 and {widths[1.8]:.3f} mm at 1.8 mm/s", tp)]


def cup(library: ToolLibrary, App, Part, out: Path) -> list[Example]:
    from freecad_conformal.jobs.feature import plan_feature
    shape = Part.makeCone(10, 20, 15).cut(Part.makeCone(7.7, 17.7, 15))
    inner = _face(shape, "cone", pick=lambda f: f.Surface.Radius)
    tp = plan_feature(inner, "shell", {"cup_height": 8.0, "layer": 1.0, "width": 2.3},
                      "inverse conical cup", part=shape)
    feeds_ = _cure_feeds(tp)
    return [Example("inverse conical cup, large tool", "wall 2.3 mm, 1 mm layers: feed",
                    "0.4 mm/s", f"{feeds_[-1]:.3g} mm/s (first layer {feeds_[0]:.3g} mm/s), "
                    "rings on the wall's centre", tp)]


def channels(library: ToolLibrary, App, Part, out: Path) -> list[Example]:
    from freecad_conformal.jobs.feature import plan_feature
    tube = Part.makeCylinder(15, 40, App.Vector(-20, 0, 0), App.Vector(1, 0, 0))
    face = _face(tube, "cylinder")
    tp = plan_feature(face, "channels", {"channels": 3, "gap": 1.0, "wall": 1.0,
                                         "wall_height": 1.0, "layer": 0.5}, "fluidic channels",
                      part=tube)
    tools = tp.metadata["tools"]
    return [Example("fluidic channels on a cylinder", "tools, smallest gap",
                    "base 0.5 mm with the large tool, walls with the small one, gap 1.0 mm",
                    f"{tools}; gap 1.0 mm; feeds {', '.join(f'{v:g}' for v in _cure_feeds(tp))} "
                    "mm/s", tp)]


def sphere_rods(library: ToolLibrary, App, Part, out: Path) -> list[Example]:
    from freecad_conformal.jobs.feature import plan_feature
    dome = Part.makeSphere(20, App.Vector(0, 0, 0), App.Vector(0, 0, 1), 0, 90)
    tp = plan_feature(dome.Faces[0], "rods", {"spacing": 3.0, "rod_length": 3.0,
                                              "rod_diameter": 1.2}, "rods on a sphere", part=dome)
    return [Example("rods on a sphere, small tool", "rod ∅ 1.2 mm: speed", "0.75 mm/s",
                    f"{_cure_feeds(tp)[0]:.3g} mm/s, {int(np.sum(tp.kind == KINDS.index('cure')))} "
                    "rods built along their axes", tp)]


def tilted_rod(library: ToolLibrary, App, Part, out: Path) -> list[Example]:
    """One 12 mm rod tilted 30° from Z, ∅ 1.2 mm: time against mask-projection SL."""
    tool = library.get("uv_small")
    tilt = math.radians(30.0)
    axis = np.array([[math.sin(tilt), 0.0, math.cos(tilt)]])
    layout = rods.RodLayout("sphere", 1e6, 1.0, 0.0, 1.2, 12.0, [], np.zeros((1, 3)), axis,
                            np.zeros(1, dtype=int))
    tp = rods.rods_toolpath(layout, tool, feeds.rod_settings(tool, [1.2])).build()
    tp.metadata["tools"] = f"T1 {tool.id}"
    cure = KINDS.index("cure")
    speed = float(tp.feed[tp.kind == cure][0]) / 60.0          # one diameter: one feed
    seconds = tp.summary().length_by_kind["cure"] / speed
    return [Example("12 mm tilted rod", "build time at 0.75 mm/s",
                    "16 s; 25 min (0.1 mm layers) and 60 min (0.05 mm) by mask projection",
                    f"{seconds:.1f} s curing ({tp.summary().time_s:.1f} s with the approach); "
                    f"{1500 / seconds:.0f}× and {3600 / seconds:.0f}× faster", tp)]


def doe_calibration() -> list[Example]:
    from freecad_conformal.process.curing_fit import fit_speed_factors
    table = np.array([(1, 1, 1, 1, .642), (-1, 1, -1, 1, .392), (1, -1, -1, 1, .737),
                      (-1, -1, 1, 1, .579), (1, 1, -1, -1, .196), (-1, 1, 1, -1, .116),
                      (1, -1, 1, -1, .714), (-1, -1, -1, -1, .203)])
    fit = fit_speed_factors(np.where(table[:, 0] > 0, 0.495, 0.231), table[:, 4] * VMAX,
                            {"B": table[:, 1], "C": table[:, 2], "D": table[:, 3]})
    best = fit.speed(0.495, {"B": 1, "C": 1, "D": 1})
    return [Example("line-curing DOE (speed ∝ power)", "optimum (+,+,+,+)",
                    "0.71207·Vmax = 2.53 mm/s (DOE location model)",
                    f"{best / VMAX:.3f}·Vmax = {best:.2f} mm/s; RMS {fit.rms_log_error:.2f} in ln v "
                    f"over the 8 runs; power exponent fitted freely {fit.free_power_exponent:.2f} "
                    "(model 1)")]


EXAMPLES = (spiral, cup, channels, sphere_rods, tilted_rod)


def run(out: Path) -> list[Example]:
    from freecad_conformal.freecad_env import import_freecad
    from freecad_conformal.paths.features.preview import write_preview
    App, Part = import_freecad()
    out.mkdir(parents=True, exist_ok=True)
    library = ToolLibrary.load()
    results: list[Example] = []
    for build in EXAMPLES:
        for example in build(library, App, Part, out):
            if example.toolpath is not None:
                stem = example.name.split(",")[0].replace(" ", "_")
                example.toolpath.save(out / f"{stem}.npz")
                write_preview(example.toolpath, out / f"{stem}.png", example.name)
            results.append(example)
    results += doe_calibration()
    lines = ["| example | quantity | published | ours |", "|---|---|---|---|"]
    lines += [f"| {e.name} | {e.quantity} | {e.published} | {e.ours} |" for e in results]
    write_text_atomic(out / "examples.md", "\n".join(lines) + "\n")
    return results


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--out", default="out/feature_examples")
    args = parser.parse_args(argv)
    for example in run(Path(args.out)):
        print(f"{example.name}: {example.quantity}\n  published: {example.published}\n"
              f"  ours:      {example.ours}")
    print(f"wrote {args.out}/examples.md", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
