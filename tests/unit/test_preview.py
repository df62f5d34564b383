"""The plan's PNG preview: every sub-part in its colour, travels in grey, thinning named."""
from __future__ import annotations

import io
from types import SimpleNamespace

import numpy as np
import pytest

from freecad_conformal.errors import PlanError
from freecad_conformal.paths import preview

Image = pytest.importorskip("PIL.Image")


def _assembly(layers: int = 3):
    """Two sub-parts of square loops, one above the other, and a travel between them."""
    square = np.array([[0, 0, 0], [20, 0, 0], [20, 20, 0], [0, 20, 0], [0, 0, 0]], dtype=float)
    paths = [SimpleNamespace(points=square + [0, 0, z + 10 * sub], subpart=sub, layer=k,
                             role="perimeter")
             for sub in (0, 1) for k, z in enumerate(np.arange(layers) * 0.2)]
    travels = [np.array([[0, 0, 1.0], [40, 40, 30.0]])]
    return SimpleNamespace(paths=paths, travels=travels)


def _render(assembly, title: str = "part: 2 sub-parts") -> np.ndarray:
    buffer = io.BytesIO()
    preview.render_png(assembly, buffer, title=title)
    image = Image.open(io.BytesIO(buffer.getvalue()))
    assert image.format == "PNG" and image.size == (preview.WIDTH, preview.HEIGHT)
    return np.asarray(image.convert("RGB"))


def _count(pixels: np.ndarray, colour) -> int:
    return int(np.all(pixels == np.array(colour), axis=-1).sum())


def test_each_sub_part_is_drawn_in_its_colour_and_travels_in_grey():
    pixels = _render(_assembly())
    first, second = preview.COLOURS[:2]
    # Paths and the legend's swatch: far more than the swatch alone (3 x 24 pixels).
    assert _count(pixels, first) > 200 and _count(pixels, second) > 200
    assert _count(pixels, preview.TRAVEL) > 20
    assert _count(pixels, preview.COLOURS[2]) == 0


def test_a_thinned_preview_says_so(monkeypatch):
    monkeypatch.setattr(preview, "MAX_DRAWN_PATHS", 2)
    thinned = _render(_assembly(layers=6), title="t")
    full = _render(_assembly(layers=1), title="t")
    # The heading grows by "(one layer in 6 drawn)": more dark text pixels at the top.
    assert (thinned[:40] < 100).sum() > (full[:40] < 100).sum() + 50


def test_a_plan_without_paths_is_refused_by_name():
    with pytest.raises(PlanError, match="no deposit paths"):
        preview.render_png(SimpleNamespace(paths=[], travels=[]), io.BytesIO())
