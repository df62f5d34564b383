"""Settings of posting and verifying a program (`post`, `verify`, the GUI's Post and Verify
objects)."""
from __future__ import annotations

from freecad_conformal.settings.plan import DEFAULT_MACHINE, machine_names
from freecad_conformal.settings.schema import Setting

#: Tool-tip and tool-axis tolerances of the linearisation (tolerances.py's defaults, restated
#: in the user's units: mm and degrees).
LINEAR_TOLERANCE_MM = 0.01
ANGULAR_TOLERANCE_DEG = 0.05

MACHINE = Setting("machine", "machine", DEFAULT_MACHINE, "machine",
                  "machine name (resources/machines) or, on the command line, a .json path",
                  group="machine", choices=machine_names, required=True)

POST_SETTINGS: tuple[Setting, ...] = (
    MACHINE,
    Setting("dialect", "text", None, "G-code dialect",
            "G-code dialect: linuxcnc, marlin, reprap, grblhal", group="machine",
            derived="the machine's dialect"),
    Setting("tolerance", "length", LINEAR_TOLERANCE_MM, "tip tolerance",
            "largest tool-tip deviation of the linearised moves", group="linearisation",
            minimum=0.0, open_minimum=True),
    Setting("angular_tolerance", "angle", ANGULAR_TOLERANCE_DEG, "axis tolerance",
            "largest tool-axis deviation of the linearised moves", group="linearisation",
            minimum=0.0, open_minimum=True, maximum=90.0),
    Setting("absolute_e", "bool", False, "absolute extrusion",
            "absolute extrusion (M82) instead of relative (M83)", group="machine",
            prop="AbsoluteE"),
)

VERIFY_SETTINGS: tuple[Setting, ...] = (
    MACHINE,
    Setting("max_position", "length", 0.01, "largest tip deviation",
            "the program fails (exit 1) when the tool tip strays further from the design",
            group="limits", minimum=0.0),
    Setting("max_angle", "angle", 0.1, "largest axis deviation",
            "the program fails (exit 1) when the tool axis turns further from the design",
            group="limits", minimum=0.0, maximum=180.0),
)
