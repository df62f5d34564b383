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
from typing import Any, Callable

import numpy as np

from freecad_conformal.fileio import write_text_atomic
from freecad_conformal.paths.features import feeds
from freecad_conformal.process.library import ToolLibrary
from freecad_conformal.toolpath import KINDS, Toolpath

VMAX = 3.556  # mm/s, METHODS section 1
PUBLISHED_POWER = 0.495  # W, the DOE's high level (METHODS section 1)


@dataclass
class Example:
    name: str
    quantity: str
    published: str
    ours: str
    toolpath: Toolpath | None = None


@dataclass(frozen=True)
class Case:
    """One published test case as the user would set it up: a part, one of its faces and the
    feature's settings (settings/feature.py keys), plus how the result is read against the
    published figure. The CLI plans it directly; the GUI builds it as Part + Feature objects."""
    name: str
    label: str                                   # object and file name stem
    build: Callable[[Any, Any], Any]             # (App, Part) -> shape
    face: Callable[[Any], str]                   # shape -> "FaceN"
    kind: str
    settings: dict[str, Any]
    compare: Callable[[Toolpath, ToolLibrary], tuple[str, str, str]]  # quantity, published, ours


def _face(kind: str, pick: Callable[[Any], float] | None = None) -> Callable[[Any], str]:
    """A picker of the face of `kind` (the one minimising `pick`, else the first)."""
    def name(shape) -> str:
        from freecad_conformal.geometry.faces import face_kind
        faces = [(i, f) for i, f in enumerate(shape.Faces, 1) if face_kind(f) == kind]
        index, _ = min(faces, key=lambda item: pick(item[1])) if pick else faces[0]
        return f"Face{index}"
    return name


def _cure_feeds(tp: Toolpath) -> list[float]:
    return sorted({round(float(f) / 60.0, 3) for f in tp.feed[tp.kind == KINDS.index("cure")]})


#: A 10 mm disc as SVG path data (the spiral's outline, carried inline by the settings).
DISC = " ".join(["M5 0"] + [f"L{5 * math.cos(t):.4f} {5 * math.sin(t):.4f}"
                            for t in np.linspace(0, 2 * math.pi, 73)[1:]] + ["Z"])


def _spiral(tp: Toolpath, library: ToolLibrary) -> tuple[str, str, str]:
    small = library.get("uv_small")
    fit = feeds.line_fit(small)
    power = feeds.material_settings(small)[1].power or PUBLISHED_POWER
    widths = {v: fit.width(power, v) for v in (1.3, 1.8)}
    return ("feed for 0.3 mm lines", "1.3 mm/s good (inner), 1.8 mm/s defects (outer)",
            f"{_cure_feeds(tp)[0]:.3g} mm/s; at {power:g} W the fit gives "
            f"{widths[1.3]:.3f} mm at 1.3 and {widths[1.8]:.3f} mm at 1.8 mm/s")


def _cup(tp: Toolpath, library: ToolLibrary) -> tuple[str, str, str]:
    feeds_ = _cure_feeds(tp)
    return ("wall 2.3 mm, 1 mm layers: feed", "0.4 mm/s",
            f"{feeds_[-1]:.3g} mm/s (first layer {feeds_[0]:.3g} mm/s), rings on the wall's centre")


def _channels(tp: Toolpath, library: ToolLibrary) -> tuple[str, str, str]:
    return ("tools, smallest gap",
            "base 0.5 mm with the large tool, walls with the small one, gap 1.0 mm",
            f"{tp.metadata['tools']}; gap 1.0 mm; feeds "
            f"{', '.join(f'{v:g}' for v in _cure_feeds(tp))} mm/s")


def _rods(tp: Toolpath, library: ToolLibrary) -> tuple[str, str, str]:
    count = int(np.sum(tp.kind == KINDS.index("cure")))
    return ("rod ∅ 1.2 mm: speed", "0.75 mm/s",
            f"{_cure_feeds(tp)[0]:.3g} mm/s, {count} rods built along their axes")


def _tilted_rod(tp: Toolpath, library: ToolLibrary) -> tuple[str, str, str]:
    speed = _cure_feeds(tp)[0]                      # one diameter: one feed
    seconds = tp.summary().length_by_kind["cure"] / speed
    return ("build time at 0.75 mm/s",
            "16 s; 25 min (0.1 mm layers) and 60 min (0.05 mm) by mask projection",
            f"{seconds:.1f} s curing ({tp.summary().time_s:.1f} s with the approach); "
            f"{1500 / seconds:.0f}× and {3600 / seconds:.0f}× faster")


TILT = math.radians(30.0)
#: The tilted rod stands alone at the pole of a small spherical cap whose pole is tilted 30°
#: from Z; rods are built along the build direction, so that is the pole too.
TILTED_AXIS = (math.sin(TILT), 0.0, math.cos(TILT))


def _tilted_cap(App, Part):
    cap = Part.makeSphere(60, App.Vector(0, 0, 0), App.Vector(0, 0, 1), 85, 90)
    cap.rotate(App.Vector(0, 0, 0), App.Vector(0, 1, 0), math.degrees(TILT))
    return cap


CASES = (
    Case("flat spiral, small tool", "flat_spiral",
         lambda App, Part: Part.makeBox(30, 30, 2, App.Vector(-15, -15, -2)),
         _face("plane", pick=lambda f: -f.CenterOfMass.z), "pattern",
         {"svg": DISC, "width": 0.3, "height": 0.3, "layer": 0.3}, _spiral),
    Case("inverse conical cup, large tool", "inverse_conical_cup",
         lambda App, Part: Part.makeCone(10, 20, 15).cut(Part.makeCone(7.7, 17.7, 15)),
         _face("cone", pick=lambda f: f.Surface.Radius), "shell",
         {"cup_height": 8.0, "layer": 1.0, "width": 2.3}, _cup),
    Case("fluidic channels on a cylinder", "fluidic_channels_on_a_cylinder",
         lambda App, Part: Part.makeCylinder(15, 40, App.Vector(-20, 0, 0), App.Vector(1, 0, 0)),
         _face("cylinder"), "channels",
         {"channels": 3, "gap": 1.0, "wall": 1.0, "wall_height": 1.0, "layer": 0.5}, _channels),
    Case("rods on a sphere, small tool", "rods_on_a_sphere",
         lambda App, Part: Part.makeSphere(20, App.Vector(0, 0, 0), App.Vector(0, 0, 1), 0, 90),
         _face("sphere"), "rods", {"spacing": 3.0, "rod_length": 3.0, "rod_diameter": 1.2},
         _rods),
    Case("12 mm tilted rod", "12_mm_tilted_rod", _tilted_cap, _face("sphere"), "rods",
         {"spacing": 20.0, "rod_length": 12.0, "rod_diameter": 1.2,
          "build_direction": TILTED_AXIS}, _tilted_rod),
)


def plan_case(case: Case, library: ToolLibrary, App, Part) -> Example:
    """Plan `case` as the `feature` command would and read it against the published figure."""
    from freecad_conformal.geometry.faces import face_by_name
    from freecad_conformal.jobs.feature import plan_feature
    shape = case.build(App, Part)
    face = face_by_name(shape, case.face(shape))
    tp = plan_feature(face, case.kind, dict(case.settings), case.name, part=shape)
    return Example(case.name, *case.compare(tp, library), tp)


def doe_calibration() -> list[Example]:
    from freecad_conformal.process.curing_fit import fit_speed_factors
    table = np.array([(1, 1, 1, 1, .642), (-1, 1, -1, 1, .392), (1, -1, -1, 1, .737),
                      (-1, -1, 1, 1, .579), (1, 1, -1, -1, .196), (-1, 1, 1, -1, .116),
                      (1, -1, 1, -1, .714), (-1, -1, -1, -1, .203)])
    fit = fit_speed_factors(np.where(table[:, 0] > 0, PUBLISHED_POWER, 0.231), table[:, 4] * VMAX,
                            {"B": table[:, 1], "C": table[:, 2], "D": table[:, 3]})
    best = fit.speed(PUBLISHED_POWER, {"B": 1, "C": 1, "D": 1})
    return [Example("line-curing DOE (speed ∝ power)", "optimum (+,+,+,+)",
                    "0.71207·Vmax = 2.53 mm/s (DOE location model)",
                    f"{best / VMAX:.3f}·Vmax = {best:.2f} mm/s; RMS {fit.rms_log_error:.2f} in ln v "
                    f"over the 8 runs; power exponent fitted freely {fit.free_power_exponent:.2f} "
                    "(model 1)")]


def run(out: Path) -> list[Example]:
    from freecad_conformal.freecad_env import import_freecad
    from freecad_conformal.paths.features.preview import write_preview
    App, Part = import_freecad()
    out.mkdir(parents=True, exist_ok=True)
    library = ToolLibrary.load()
    results: list[Example] = []
    for case in CASES:
        example = plan_case(case, library, App, Part)
        assert example.toolpath is not None
        example.toolpath.save(out / f"{case.label}.npz")
        write_preview(example.toolpath, out / f"{case.label}.png", example.name)
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
