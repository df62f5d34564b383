"""Conformal preferences: default machine, tool library location, tolerances.

Stored in FreeCAD's parameters under PARAM_PATH; `PreferencesPage` is the page FreeCAD shows
under Edit > Preferences > Conformal. Readers return the default when nothing is stored.
"""
from __future__ import annotations

from pathlib import Path

import FreeCAD

from freecad_conformal import tolerances
from freecad_conformal.gui.qt import QtWidgets, translate
from freecad_conformal.gui.widgets import quantity_field, quantity_value, set_quantity
from freecad_conformal.settings.plan import DEFAULT_MACHINE, PLAN_SETTINGS
from freecad_conformal.settings.sections import SECTIONS_SETTINGS

PARAM_PATH = "User parameter:BaseApp/Preferences/Mod/Conformal"


def _params():
    return FreeCAD.ParamGet(PARAM_PATH)


def machine_names() -> list[str]:
    """Machines shipped in resources/machines (file names without .json)."""
    from freecad_conformal.settings.plan import machine_names as names

    return sorted(names())


def default_machine() -> str:
    return _params().GetString("DefaultMachine", DEFAULT_MACHINE)


def tool_library_dir() -> Path | None:
    """The user tool folder chosen here, or None for the library's own default."""
    text = _params().GetString("ToolLibraryDir", "")
    return Path(text).expanduser() if text else None


def chord_tolerance() -> float:
    """Chord tolerance (mm) for polygons derived from exact section wires."""
    return _params().GetFloat("ChordTolerance", tolerances.DEFAULT_CHORD_TOLERANCE)


def background_recompute() -> bool:
    """Whether recomputes the GUI did not start run in worker processes (gui/background.py)."""
    return _params().GetBool("RecomputeInBackground", True)


def set_background_recompute(on: bool) -> None:
    _params().SetBool("RecomputeInBackground", bool(on))


def section_spacing() -> float:
    """Default spacing (mm) of new Sections objects."""
    return _params().GetFloat("SectionSpacing", _default(SECTIONS_SETTINGS, "layer"))


def layer_height() -> float:
    """Default layer height (mm) of new Jobs (the plan setting's default unless set here)."""
    return _params().GetFloat("LayerHeight", _default(PLAN_SETTINGS, "layer_height"))


def _default(settings, key: str):
    """The schema's default: a preference left unset means what the command line does."""
    return next(s.default for s in settings if s.key == key)


class PreferencesPage:
    """The preference page (FreeCADGui.addPreferencePage(PreferencesPage, 'Conformal'))."""

    def __init__(self) -> None:
        self.form = QtWidgets.QWidget()
        self.form.setWindowTitle(translate("Conformal", "Conformal"))
        layout = QtWidgets.QFormLayout(self.form)
        self.machine = QtWidgets.QComboBox()
        self.machine.addItems(machine_names())
        self.library_dir = QtWidgets.QLineEdit()
        self.library_dir.setPlaceholderText(translate(
            "Conformal", "default: <FreeCAD user data>/Conformal/tools"))
        self.chord = quantity_field("mm", tolerances.DEFAULT_CHORD_TOLERANCE, 1e-6, 10.0)
        self.spacing = quantity_field("mm", _default(SECTIONS_SETTINGS, "layer"), 1e-3, 100.0)
        self.layer = quantity_field("mm", _default(PLAN_SETTINGS, "layer_height"), 1e-3, 100.0)
        self.background = QtWidgets.QCheckBox(translate(
            "Conformal", "Recompute in the background (property editor, Ctrl+R, opened files)"))
        layout.addRow(translate("Conformal", "Default machine"), self.machine)
        layout.addRow(translate("Conformal", "Tool library folder"), self.library_dir)
        layout.addRow(translate("Conformal", "Chord tolerance"), self.chord)
        layout.addRow(translate("Conformal", "Default section spacing"), self.spacing)
        layout.addRow(translate("Conformal", "Default layer height (jobs)"), self.layer)
        layout.addRow(self.background)

    def loadSettings(self) -> None:  # noqa: N802 - FreeCAD's name
        index = self.machine.findText(default_machine())
        self.machine.setCurrentIndex(max(index, 0))
        folder = tool_library_dir()
        self.library_dir.setText(str(folder) if folder else "")
        set_quantity(self.chord, chord_tolerance())
        set_quantity(self.spacing, section_spacing())
        set_quantity(self.layer, layer_height())
        self.background.setChecked(background_recompute())

    def saveSettings(self) -> None:  # noqa: N802 - FreeCAD's name
        params = _params()
        params.SetString("DefaultMachine", self.machine.currentText())
        params.SetString("ToolLibraryDir", self.library_dir.text().strip())
        params.SetFloat("ChordTolerance", quantity_value(self.chord))
        params.SetFloat("SectionSpacing", quantity_value(self.spacing))
        params.SetFloat("LayerHeight", quantity_value(self.layer))
        set_background_recompute(self.background.isChecked())
