"""The planar region of a pattern from the feature settings: --svg, --text or --outline."""
from __future__ import annotations

import re
from pathlib import Path

from freecad_conformal.errors import GeometryError, PlanError
from freecad_conformal.paths.features import outlines


def outline_region(s, what: str):
    """The pattern's planar region from `s.svg`, `s.text` or `s.outline` (exactly one)."""
    given = [name for name in ("svg", "text", "outline") if getattr(s, name, None)]
    if len(given) != 1:
        raise PlanError(f"{what}: give exactly one of --svg, --text, --outline (got {given or 'none'})")
    if s.svg:
        text = _svg_text(s.svg, what)
        if "<svg" in text:
            found = re.findall(r'\sd="([^"]+)"', text)
            if not found:
                raise GeometryError(f"{what}: SVG file {s.svg} has no <path d=...>")
            text = " ".join(found)
        return outlines.region_from_rings(outlines.svg_path_rings(text), f"{what} SVG outline")
    if s.text:
        return outlines.region_from_rings(outlines.text_rings(s.text, s.text_size), f"{what} text")
    if s.outline.lower().endswith(".brep"):
        from freecad_conformal.freecad_env import import_freecad
        _, Part = import_freecad()
        shape = Part.read(s.outline)
    else:
        from freecad_conformal.geometry.solids import load_shape
        shape = load_shape(s.outline)
    return outlines.region_from_rings(outlines.wire_rings(shape), what)


#: Path data always opens with a moveto; a file name that starts with M and names no file is
#: taken as path data too, so a typo'd file name is reported by the SVG parser, naming it.
_PATH_DATA = re.compile(r"^\s*[Mm]\s*[-+.\d]")


def _svg_text(svg: str, what: str) -> str:
    """The SVG text of `svg`: a file's content, or `svg` itself when it is path data (how a
    document object carries its pattern without a file beside it)."""
    path = Path(svg)
    if _PATH_DATA.match(svg) and not _is_file(path):
        return svg
    try:
        return path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise PlanError(f"{what}: SVG file {svg} does not exist") from None
    except UnicodeDecodeError as exc:
        raise PlanError(f"{what}: SVG file {svg} is not UTF-8 text ({exc.reason} at byte "
                        f"{exc.start})") from None


def _is_file(path: Path) -> bool:
    try:
        return path.is_file()
    except OSError:          # path data longer than a file name can be
        return False
