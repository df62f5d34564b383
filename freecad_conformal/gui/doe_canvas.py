"""The half-normal plot of a DOE analysis on a matplotlib canvas inside Qt.

matplotlib picks the Qt binding FreeCAD already loaded (PySide2 on 0.20, PySide6 on 1.x).
The panels are drawn by process.doe_plot, the same code as the command line's PNG.
"""
from __future__ import annotations

from freecad_conformal.errors import ProcessError
from freecad_conformal.gui.qt import QtWidgets
from freecad_conformal.process.doe.analysis import Analysis

#: Figure size (inches) of one panel; the canvas scales it to the dock's width.
PANEL_SIZE = (4.0, 3.2)


def make_canvas(parent=None):
    """A matplotlib canvas widget, or a QLabel explaining how to install matplotlib."""
    try:
        from matplotlib.backends.backend_qtagg import FigureCanvasQTAgg
        from matplotlib.figure import Figure
    except ImportError:
        label = QtWidgets.QLabel("The half-normal plot needs matplotlib "
                                 "(Debian: apt-get install python3-matplotlib; "
                                 "pip: pip install matplotlib)", parent)
        label.setWordWrap(True)
        return label
    canvas = FigureCanvasQTAgg(Figure(figsize=(2 * PANEL_SIZE[0], PANEL_SIZE[1])))
    canvas.setParent(parent)
    canvas.setMinimumHeight(260)
    return canvas


def draw_half_normal(canvas, result: Analysis) -> None:
    """Draw the effects on the mean (and on ln s² when known), model terms in red."""
    if not hasattr(canvas, "figure"):
        raise ProcessError("matplotlib is not installed: no half-normal plot")
    # the panel drawing is the command line's (doe_plot), shared rather than copied
    from freecad_conformal.process.doe.plot import half_normal_panel

    figure = canvas.figure
    figure.clear()
    panels = 2 if result.effects_ln_s2 is not None else 1
    axes = figure.subplots(1, panels, squeeze=False)[0]
    half_normal_panel(axes[0], result.half_normal("mean"), result.lenth_mean,
           set(result.location.coefficients), "effects on the mean")
    if panels == 2:
        half_normal_panel(axes[1], result.half_normal("ln_s2"), result.lenth_ln_s2,
               set(result.dispersion.coefficients), "effects on ln s²")
    figure.tight_layout()
    canvas.draw()
