"""Settings of a conformal feature on one face (`feature` command, the GUI's Feature object).
Keys are the attribute names the feature planners read (paths/features/planners.py)."""
from __future__ import annotations

from dataclasses import replace

from freecad_conformal.settings.schema import Setting

KINDS = ("rods", "shell", "pattern", "channels", "texture")

_SETTINGS: tuple[Setting, ...] = (
    Setting("tool", "text", None, "tool", "tool id", group="tool",
            derived="uv_small for rods and pattern walls, uv_large for shells; channels "
                    "choose by curvature"),
    Setting("feed", "feed", None, "curing feed", "curing feed", group="tool", minimum=0.0, open_minimum=True,
            derived="the tool's curing fit for the width or rod diameter"),
    Setting("collision_rule", "choice", "envelope", "collision rule",
            "how moves are checked: the tool's real envelope, or the published rule (i) "
            "for the rod layout (travels still checked)", group="tool",
            choices=("envelope", "published")),
    Setting("tilt", "angle", 0.0, "tool tilt", "tilt of the tool from the surface normal (shell)",
            group="tool", minimum=-90.0, maximum=90.0),
    Setting("layer", "length", 1.0, "layer thickness", "layer thickness", group="tool",
            prop="LayerThickness", minimum=0.0, open_minimum=True),
    Setting("build_direction", "direction", (0.0, 0.0, 1.0), "build direction",
            "direction tilts are measured from", group="tool"),
    Setting("spacing", "length", 3.0, "rod spacing", "rod spacing d on the surface",
            group="rods", minimum=0.0, open_minimum=True),
    Setting("rod_length", "length", 3.0, "rod length", "rod height l", group="rods",
            minimum=0.0, open_minimum=True),
    Setting("rod_diameter", "length", 1.2, "rod diameter", "rod diameter a", group="rods",
            minimum=0.0, open_minimum=True),
    Setting("diameter_profile", "numbers", None, "diameter profile",
            "diameters along each rod, base to tip (varying speed)", group="rods",
            derived="the rod diameter all along"),
    Setting("rings", "int", None, "rings", "rings N on a sphere", group="rods", minimum=1,
            derived="floor(W/θ)"),
    Setting("width", "length", None, "shell width", "ring spacing / line width", group="shell",
            minimum=0.0, open_minimum=True, derived="the tool's"),
    Setting("layers", "int", 1, "shell layers", "shell layers", group="shell", minimum=1),
    Setting("cup_height", "length", None, "cup height",
            "on a cone face: build an inverse conical cup wall this tall", group="shell",
            minimum=0.0, open_minimum=True, derived="no cup"),
    Setting("first_layer", "length", 0.5, "cup first layer", "cup first layer", group="shell",
            minimum=0.0, open_minimum=True),
    Setting("svg", "text", None, "SVG path", "an .svg file, a file holding one SVG path 'd' string, "
            "or the 'd' string itself (M...)", group="pattern", derived="none"),
    Setting("text", "text", None, "pattern text", "text to wrap onto the face", group="pattern",
            prop="PatternText", derived="none"),
    Setting("text_size", "length", 5.0, "text size", "text size", group="pattern",
            minimum=0.0, open_minimum=True),
    Setting("outline", "text", None, "outline file",
            "BREP/STEP/FCStd whose closed XY wires are the outline", group="pattern",
            derived="none"),
    Setting("height", "length", 1.0, "pattern height", "pattern height along the normal",
            group="pattern", minimum=0.0, open_minimum=True),
    Setting("fill", "choice", "contours", "pattern fill", "how the pattern is filled",
            group="pattern", choices=("contours", "zigzag")),
    Setting("at", "numbers", None, "pattern centre", "face parameters u,v of the pattern centre",
            group="placement", derived="the point facing the build direction"),
    Setting("at_point", "numbers", None, "pattern centre point",
            "x,y,z of a point projected onto the face as the pattern centre", group="placement",
            derived="the point facing the build direction"),
    Setting("channels", "int", 3, "channels", "number of parallel channels", group="channels",
            minimum=1),
    Setting("channel_length", "length", 15.0, "channel length", "channel length",
            group="channels", minimum=0.0, open_minimum=True),
    Setting("gap", "length", 1.0, "channel width", "channel width", group="channels",
            minimum=0.0, open_minimum=True),
    Setting("wall", "length", 1.0, "wall width", "wall width", group="channels",
            minimum=0.0, open_minimum=True),
    Setting("wall_height", "length", 1.0, "wall height", "wall height", group="channels",
            minimum=0.0, open_minimum=True),
    Setting("pitch", "length", 3.0, "stamp pitch", "distance between texture stamps",
            group="texture", minimum=0.0, open_minimum=True),
    Setting("thickness", "length", 0.5, "texture thickness", "thickness of each stamp",
            group="texture", minimum=0.0, open_minimum=True),
    Setting("stamp", "choice", "travel", "stamp mode",
            "thickness set by moving the masked tool out (travel) or by the dwell time",
            group="texture", choices=("travel", "dwell")),
    Setting("layout", "choice", "grid", "texture layout",
            "stamps on a grid about the centre, or along the u iso-curve through it",
            group="texture", choices=("grid", "curve")),
    Setting("extent", "length", 10.0, "texture extent", "size of the stamped area (grid side "
            "or curve length)", group="texture", minimum=0.0, open_minimum=True),
)

#: A setting grouped under a kind applies to features of that kind only (the task panel
#: shows it for that kind; help texts say "only with kind rods").
_PLACED = ("pattern", "channels", "texture")
FEATURE_SETTINGS: tuple[Setting, ...] = tuple(
    replace(s, only_when=("kind", (s.group,))) if s.group in KINDS
    else replace(s, only_when=("kind", _PLACED)) if s.group == "placement" else s
    for s in _SETTINGS)
