"""Settings of a decomposition (`decompose` command, the GUI's Decomposition object)."""
from __future__ import annotations

from freecad_conformal.settings.plan import ROOT, ROOT_SEARCH
from freecad_conformal.settings.schema import Setting

#: Centroidal-axis methods (decomposition/decompose.METHODS, restated: settings stay pure).
METHODS = ("true-direction", "published")

DECOMPOSE_SETTINGS: tuple[Setting, ...] = (
    Setting("overhang", "angle", 45.0, "allowed overhang",
            "allowed overhang from the build direction", group="decomposition",
            prop="OverhangAngle", minimum=0.0, maximum=90.0, open_maximum=True),
    Setting("method", "choice", "true-direction", "axis method",
            "centroidal axis: follow inclined members (true-direction), or turn to the "
            "nearest of ±X, ±Y, ±Z (published)", group="decomposition", choices=METHODS),
    Setting("tool", "text", "fdm_0p4", "tool",
            "tool whose envelope is checked when ordering the sub-parts", group="decomposition"),
    Setting("max_subparts", "int", 24, "maximum sub-parts",
            "stop splitting beyond this many sub-parts", group="decomposition",
            prop="MaxSubParts", minimum=1),
    ROOT,
    ROOT_SEARCH,
    Setting("collision", "bool", True, "collision check",
            "order the sub-parts so the tool envelope clears what is built (off: skip it)",
            group="decomposition", prop="CollisionCheck"),
)
