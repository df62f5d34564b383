"""Tiny generated parts for the batch tests: STEP, BREP, an FCStd with bodies, a broken file.

Heights are whole millimetres so a 1 mm layer gives a known layer count per part.
"""
from __future__ import annotations

from pathlib import Path

from freecad_conformal.jobs.batch.fcstd import make_workbench_types_loadable
from freecad_conformal.freecad_env import import_freecad

#: part name in the report -> layers at --layer 1 --bead-width 1 (a layer no taller than
#: its bead is wide): the part's length in mm along the direction its plan builds it (with
#: 1 mm beads the plan stands the bodies of two.FCStd, 8 x 6 x 4 and 8 x 6 x 3 mm, on an end).
EXPECTED_LAYERS = {"box.step": 6, "cyl.brep": 5, "two.FCStd#Left": 8, "two.FCStd#Right": 6}

BROKEN_STEP = "ISO-10303-21;\nthis is not a STEP file\n"


def make_two_body_document(path: Path) -> Path:
    """two.FCStd: PartDesign bodies Left (4 mm tall) and Right (3 mm), side by side."""
    App, _Part = import_freecad()
    make_workbench_types_loadable()
    doc = App.newDocument("BatchTwoBodies")
    try:
        for name, height, x in (("Left", 4, 0.0), ("Right", 3, 20.0)):
            body = doc.addObject("PartDesign::Body", name)
            box = doc.addObject("PartDesign::AdditiveBox", f"{name}Box")
            body.addObject(box)
            box.Length, box.Width, box.Height = 8, 6, height
            body.Placement.Base = App.Vector(x, 0, 0)
        doc.recompute()
        doc.saveAs(str(path))
    finally:
        App.closeDocument(doc.Name)
    return path


def make_parts(folder: Path) -> dict[str, Path]:
    """box.step (6 mm tall), cyl.brep (5 mm), two.FCStd (bodies 4 and 3 mm), broken.step."""
    _App, Part = import_freecad()
    folder.mkdir(parents=True, exist_ok=True)
    files = {"box": folder / "box.step", "cyl": folder / "cyl.brep",
             "two": folder / "two.FCStd", "broken": folder / "broken.step"}
    Part.makeBox(10, 8, 6).exportStep(str(files["box"]))
    Part.makeCylinder(4, 5).exportBrep(str(files["cyl"]))
    make_two_body_document(files["two"])
    files["broken"].write_text(BROKEN_STEP, encoding="ascii")
    return files
