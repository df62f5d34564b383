"""Exact OCC sections versus trimesh on a 1 µm mesh, measured in the same run.

For bottle.brep, CrankArm.brep and Pump_Nut.brep at 0.2 mm layers along Z:
- ours: `planar_sections` (exact faces: area, centroid, loops) with 1 and 2 processes;
- peer: trimesh `section_multiplane` on an STL tessellated at 1 µm chord deviation
  (FreeCAD MeshPart), plus the polygons' area and centroid so both produce the same data.
Prints layers per second, the ratio, the worst area error of each (trimesh's against our
areas; ours against a dense polygon on our exact wires, which checks OCC's integration),
and how many layers fell back from the face-by-face cut to the Boolean.

Usage: .venv/bin/python benchmarks/sections.py [PARTS_DIR]
"""
from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from freecad_conformal.freecad_env import import_freecad  # noqa: E402
from freecad_conformal.geometry.loops import dense_area  # noqa: E402
from freecad_conformal.geometry.sections import PlanarSlicer, planar_sections, uniform_heights  # noqa: E402

PARTS = ("bottle.brep", "CrankArm.brep", "Pump_Nut.brep")
LAYER = 0.2
MESH_DEFLECTION = 0.001  # 1 µm largest chord deviation, as the issue asks


def trimesh_sections(stl: Path, heights: list[float]) -> tuple[float, list[float]]:
    import trimesh

    mesh = trimesh.load(str(stl))
    start = time.perf_counter()
    paths = mesh.section_multiplane(plane_origin=[0, 0, 0], plane_normal=[0, 0, 1], heights=heights)
    areas = []
    for path in paths:
        if path is None:
            areas.append(0.0)
            continue
        polygons = path.polygons_full
        area = sum(p.area for p in polygons)
        if area:
            sum((np.array(p.centroid.coords[0]) * p.area for p in polygons), np.zeros(2)) / area
        areas.append(area)
    return time.perf_counter() - start, areas


def dense_error(layer) -> float:
    """Relative difference between the layer's OCC area and the shoelace area of its own
    wires sampled densely: checks the integration, not OCC against itself."""
    return abs(dense_area(layer.faces, layer.frame) - layer.area) / layer.area


def main() -> None:
    App, Part = import_freecad()
    import MeshPart

    parts_dir = Path(sys.argv[1] if len(sys.argv) > 1 else
                     os.environ.get("CONFORMAL_PARTS", Path(__file__).resolve().parents[2] / "shared" / "parts"))
    print(f"{'part':16} {'layers':>6} {'ours 1p l/s':>12} {'ours 2p l/s':>12} {'trimesh l/s':>12} "
          f"{'ratio 2p/tm':>11} {'our err':>9} {'trimesh err':>11} {'mesh tris':>9} {'boolean':>9}")
    with tempfile.TemporaryDirectory() as tmp:
        for name in PARTS:
            shape = Part.read(str(parts_dir / name))
            heights = uniform_heights(shape, (0, 0, 1), LAYER)
            slicer = PlanarSlicer(shape, (0, 0, 1))
            start = time.perf_counter()
            ours = planar_sections(shape, heights=heights)
            t1 = time.perf_counter() - start
            slicer.sections(heights)     # only to count the layers the Boolean took
            start = time.perf_counter()
            planar_sections(shape, heights=heights, workers=2)
            t2 = time.perf_counter() - start
            mesh = MeshPart.meshFromShape(Shape=shape, LinearDeflection=MESH_DEFLECTION,
                                          AngularDeflection=0.5, Relative=False)
            stl = Path(tmp) / f"{name}.stl"
            mesh.write(str(stl))
            t_peer, peer_areas = trimesh_sections(stl, heights)
            exact = np.array([layer.area for layer in ours.layers])
            # Our areas are OCC face areas; their error is checked against a dense polygon on
            # the same exact wires, on a sample of layers.
            sample = ours.layers[:: max(1, len(heights) // 20)]
            ours_err = max((dense_error(layer) for layer in sample if layer.faces), default=0.0)
            mask = exact > 1e-9
            peer_err = np.max(np.abs(np.array(peer_areas)[mask] - exact[mask]) / exact[mask])
            n = len(heights)
            print(f"{name:16} {n:6d} {n / t1:12.1f} {n / t2:12.1f} {n / t_peer:12.1f} "
                  f"{t_peer / t2:11.2f} {ours_err:9.1e} {peer_err:11.1e} {mesh.CountFacets:9d} "
                  f"{slicer.counts['boolean']:9d}")


if __name__ == "__main__":
    main()
