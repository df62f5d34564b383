"""Planar outlines for patterns: FreeCAD wires/sketches, SVG path data, and text.

Each source becomes a shapely region in the pattern plane (mm), holes by the even-odd rule,
so a letter's counter or an SVG sub-path inside another is a hole. The SVG parser reads the
subset M, L, H, V, C, Q, Z (absolute and relative), which is what outline exports of fonts
and drawing programs use for filled shapes; curves are flattened to `tolerance`.
"""
from __future__ import annotations

import math
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import shapely
from shapely.geometry import Polygon

from freecad_conformal.errors import GeometryError
from freecad_conformal.tolerances import COINCIDENT_POINTS

#: Flattening tolerance of curves in outlines (mm): a tenth of the finest line (0.2 mm).
OUTLINE_TOLERANCE = 0.02

_TOKEN = re.compile(r"[MmLlHhVvCcQqZz]|[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
FONT_CANDIDATES = ("/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
                   "/usr/share/fonts/dejavu/DejaVuSans.ttf",
                   "/usr/share/fonts/truetype/liberation2/LiberationSans-Regular.ttf")


def region_from_rings(rings: list[np.ndarray], what: str = "outline"):
    """Even-odd region of closed rings (N, 2)."""
    region = Polygon()
    for ring in rings:
        if len(ring) < 3:
            continue
        polygon = shapely.make_valid(Polygon(ring))
        region = region.symmetric_difference(polygon)
    if region.is_empty or region.area <= 0:
        raise GeometryError(f"{what} encloses no area")
    return region


def _bezier(points: np.ndarray, tolerance: float) -> np.ndarray:
    """Flatten a quadratic or cubic Bézier (control points (k, 2)) to within `tolerance`."""
    span = float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum())
    count = max(int(math.ceil(math.sqrt(span / max(tolerance, COINCIDENT_POINTS)))), 2)
    t = np.linspace(0.0, 1.0, count + 1)[1:, None]
    if len(points) == 3:
        p0, p1, p2 = points
        return (1 - t) ** 2 * p0 + 2 * (1 - t) * t * p1 + t ** 2 * p2
    p0, p1, p2, p3 = points
    return (1 - t) ** 3 * p0 + 3 * (1 - t) ** 2 * t * p1 + 3 * (1 - t) * t ** 2 * p2 + t ** 3 * p3


def svg_path_rings(data: str, tolerance: float = OUTLINE_TOLERANCE, flip_y: bool = True) -> list[np.ndarray]:
    """Closed rings of an SVG path `d` string (subset M L H V C Q Z); y flipped (SVG's y runs
    down) unless `flip_y` is False. Raises GeometryError on anything outside the subset."""
    tokens = _TOKEN.findall(data)
    leftover = _TOKEN.sub("", data).replace(",", " ").strip()
    if leftover:
        raise GeometryError(f"SVG path: unsupported content {leftover[:20]!r} (supported: "
                            "M, L, H, V, C, Q, Z and numbers)")
    rings, ring = [], []
    current = np.zeros(2)
    start = np.zeros(2)
    command = None
    i = 0

    def numbers(n: int) -> np.ndarray:
        nonlocal i
        values = tokens[i:i + n]
        if len(values) < n or any(v.isalpha() for v in values):
            raise GeometryError(f"SVG path: command {command} needs {n} numbers near token {i}")
        i += n
        return np.array([float(v) for v in values])

    while i < len(tokens):
        if tokens[i].isalpha():
            command = tokens[i]
            i += 1
            if command in "Zz":
                if len(ring) >= 3:
                    rings.append(np.array(ring))
                ring, current = [], start.copy()
                continue
        if command is None:
            raise GeometryError("SVG path must start with a command (M)")
        relative = command.islower()
        base = current if relative else np.zeros(2)
        op = command.upper()
        if op == "M":
            if len(ring) >= 3:
                rings.append(np.array(ring))
            current = base + numbers(2)
            start = current.copy()
            ring = [current.copy()]
            command = "l" if relative else "L"      # further pairs are line-tos
        elif op == "L":
            current = base + numbers(2)
            ring.append(current.copy())
        elif op == "H":
            current = np.array([(current[0] if relative else 0.0) + numbers(1)[0], current[1]])
            ring.append(current.copy())
        elif op == "V":
            current = np.array([current[0], (current[1] if relative else 0.0) + numbers(1)[0]])
            ring.append(current.copy())
        elif op in "CQ":
            k = 3 if op == "C" else 2
            controls = numbers(2 * k).reshape(k, 2) + base
            ring.extend(_bezier(np.vstack((current, controls)), tolerance))
            current = controls[-1].copy()
    if len(ring) >= 3:
        rings.append(np.array(ring))
    if flip_y:
        rings = [r * np.array([1.0, -1.0]) for r in rings]
    return rings


#: Outline wires whose Z spread exceeds this (mm) are not in a plane parallel to XY; a
#: sketch's points agree in Z to rounding, so 1 µm only refuses a real tilt.
PLANAR_OUTLINE = 1e-6


def wire_rings(shape, tolerance: float = OUTLINE_TOLERANCE) -> list[np.ndarray]:
    """Closed wires of a FreeCAD shape (sketch, wire, face, compound) in its XY plane."""
    rings = []
    for wire in shape.Wires:
        if not wire.isClosed():
            raise GeometryError(f"outline wire with {len(wire.Edges)} edges is not closed")
        points = np.array([tuple(p) for p in wire.discretize(Deflection=tolerance)])
        if np.ptp(points[:, 2]) > PLANAR_OUTLINE:
            raise GeometryError("outline wires must lie in a plane parallel to XY")
        rings.append(points[:-1, :2] if np.allclose(points[0], points[-1]) else points[:, :2])
    if not rings:
        raise GeometryError("outline shape has no closed wire")
    return rings


def find_font() -> Path:
    """A TrueType font for text patterns: DejaVu Sans if installed, else fontconfig's match."""
    for candidate in FONT_CANDIDATES:
        if Path(candidate).is_file():
            return Path(candidate)
    if shutil.which("fc-match"):
        found = subprocess.run(["fc-match", "-f", "%{file}", "sans:style=Regular"],
                               capture_output=True, text=True, check=False).stdout.strip()
        if found and Path(found).is_file():
            return Path(found)
    raise GeometryError("no TrueType font found for text patterns (Debian: apt-get install "
                        "fonts-dejavu-core)")


def text_rings(text: str, size: float, font: str | Path | None = None,
               tolerance: float = OUTLINE_TOLERANCE) -> list[np.ndarray]:
    """Outlines of `text` at cap height about `size` mm (FreeCAD's makeWireString)."""
    from freecad_conformal.freecad_env import import_freecad

    _, Part = import_freecad()
    if not text.strip():
        raise GeometryError("text pattern: the text is empty")
    font_path = Path(font) if font else find_font()
    rings = []
    for character in Part.makeWireString(text, str(font_path.parent) + "/", font_path.name,
                                         float(size), 0.0):
        for wire in character:
            points = np.array([tuple(p) for p in wire.discretize(Deflection=tolerance)])
            rings.append(points[:, :2])
    if not rings:
        raise GeometryError(f"text pattern {text!r}: the font gave no outline")
    return rings
