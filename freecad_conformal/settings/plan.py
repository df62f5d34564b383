"""The plan job's settings (`plan`, `batch` and the GUI's Job object): machine, tool, layers,
paths. jobs/options.py turns checked values into the planner's typed options."""
from __future__ import annotations

from freecad_conformal.settings.schema import Setting

DEFAULT_MACHINE = "trunnion_ac"
#: Layer modes whose thickness varies between the minimum and maximum layer heights.
VARIABLE_LAYERS = ("layer_mode", ("adaptive", "cusp"))


def machine_names() -> tuple[str, ...]:
    """Shipped machines (resources/machines), the default first (an enumeration's default)."""
    from freecad_conformal import RESOURCES

    names = sorted(p.stem for p in (RESOURCES / "machines").glob("*.json"))
    return tuple(sorted(names, key=lambda name: name != DEFAULT_MACHINE))


ROOT = Setting("root", "direction", "auto", "root direction",
               "build direction of each solid's first sub-part: auto (as placed unless "
               "turning the solid leaves less overhang), 'as placed' (+Z) or x,y,z",
               group="machine", choices=("auto",))

#: How many roots an "auto" root plans each solid from (decomposition/decompose.py).
ROOT_SEARCHES = ("quick", "thorough")
ROOT_SEARCH = Setting("root_search", "choice", "quick", "root search",
                      "with an auto root, quick plans each solid as placed, on its best "
                      "axis and on a few directions of least overhang whole; thorough also "
                      "turned over, where its split may keep far less overhang (CrankArm: "
                      "647 mm² against 1,170) at several seconds more", group="machine",
                      choices=ROOT_SEARCHES)

#: What the choice among candidate plans minimises (jobs/search.py).
OBJECTIVES = ("balanced", "time", "material")

#: Processes a plan can use: deposition only, or deposition and milling (jobs/hybrid.py).
PROCESSES = ("additive", "hybrid")
HYBRID_ONLY = ("process", ("hybrid",))

PLAN_SETTINGS: tuple[Setting, ...] = (
    Setting("machine", "machine", DEFAULT_MACHINE, "machine",
            "machine name (resources/machines) or, on the command line, a .json path",
            group="machine", choices=machine_names),
    Setting("tool", "text", "fdm_0p4", "tool", "tool id in the tool library", group="machine"),
    Setting("material", "text", None, "material", "material of the tool's settings",
            group="machine", derived="the tool's first material"),
    Setting("dialect", "text", None, "G-code dialect", "G-code dialect", group="machine",
            derived="the machine's dialect"),
    ROOT,
    ROOT_SEARCH,
    Setting("decompose", "bool", True, "decompose",
            "split each solid into support-free sub-parts (off, or on a machine that cannot "
            "tilt the tool: one sub-part per solid)",
            group="machine"),
    Setting("objective", "choice", "balanced", "objective",
            "what the choice among candidate plans (orientations, decompositions) minimises "
            "once residual overhang is least: estimated time, material, or balanced (both, "
            "each relative to the least among the candidates)", group="machine",
            choices=OBJECTIVES),
    Setting("section_workers", "int", 0, "section workers",
            "processes cutting sections at once (0: every core for large parts when run "
            "from Python; one inside FreeCAD, in a batch worker and for small parts)",
            group="machine", prop="", minimum=0),
    Setting("process", "choice", "additive", "process",
            "additive: deposition only; hybrid: deposit each layer with a stock allowance "
            "and mill it to shape (3-D layers faced, walls finished, holes cut; METHODS "
            "section 6)", group="hybrid", choices=PROCESSES),
    Setting("mill_tool", "text", "endmill_6mm", "mill tools",
            "end mill id(s) in the tool library, comma-separated: the first finishes walls "
            "and faces 3-D layers, any flat one may cut holes (the widest that fits); a "
            "V-bit (vbit_30deg_6mm) runs along sharp concave edges the first leaves stock "
            "in, a ball end mill (ball_endmill_6mm) finishes curved faces",
            group="hybrid", only_when=HYBRID_ONLY),
    Setting("stock_allowance", "length", 0.5, "stock allowance",
            "how much wider than the part each layer is deposited, for the mill to finish",
            group="hybrid", minimum=0.0, only_when=HYBRID_ONLY),
    Setting("fill_holes_below", "length", None, "fill holes below",
            "round holes narrower than this are deposited over and cut afterwards (holes "
            "across the build direction always are)", group="hybrid", minimum=0.0,
            derived="2 x bead width", only_when=HYBRID_ONLY),
    Setting("material_check", "bool", True, "material check",
            "simulate the material (deposits minus what the mill sweeps, exact solids) and "
            "compare it with the part", group="hybrid", only_when=HYBRID_ONLY),
    Setting("layer_height", "length", 0.2, "layer height",
            "layer height; also the nominal height of adaptive and 3-D layers",
            group="layers", aliases=("--layer",), minimum=0.0, open_minimum=True),
    Setting("layer_mode", "choice", "uniform", "layer mode",
            "uniform layers, adaptive (volume difference) or cusp-height limited",
            group="layers", choices=("uniform", "adaptive", "cusp")),
    Setting("layer_min", "length", None, "minimum layer height",
            "thinnest adaptive layer", group="layers", minimum=0.0, open_minimum=True,
            derived="0.5 x layer height", only_when=VARIABLE_LAYERS),
    Setting("layer_max", "length", None, "maximum layer height",
            "thickest adaptive layer", group="layers", minimum=0.0, open_minimum=True,
            derived="1.5 x layer height, at most the bead width",
            only_when=VARIABLE_LAYERS),
    Setting("max_volume_difference", "volume", 2.0, "maximum volume difference",
            "volume between a layer and its exact slab", group="layers",
            minimum=0.0, open_minimum=True, only_when=("layer_mode", ("adaptive",))),
    Setting("max_cusp", "length", 0.05, "maximum cusp height", "cusp height limit",
            group="layers", minimum=0.0, open_minimum=True, only_when=("layer_mode", ("cusp",))),
    Setting("tilt", "bool", True, "3-D layers",
            "tilt the layer planes where a sub-part's centroidal axis bends and following "
            "it spares overhang planar layers would leave (off: every layer planar)",
            group="layers", prop="TiltLayers"),
    Setting("bead_width", "length", None, "bead width", "deposited bead width", group="paths",
            minimum=0.0, open_minimum=True, derived="the material's width"),
    Setting("perimeters", "int", 2, "perimeters", "perimeter loops per layer", group="paths",
            minimum=0),
    Setting("infill", "percent", 20.0, "infill density", "sparse infill density",
            group="paths", minimum=0.0, maximum=100.0),
    Setting("infill_angle", "angle", None, "infill angle", "direction of the infill lines",
            group="paths", derived="the direction with the fewest turns"),
    Setting("seam", "choice", "aligned", "seam", "where perimeter loops start",
            group="paths", choices=("aligned", "nearest", "sharpest")),
    Setting("solid_layers", "int", 3, "solid layers", "top and bottom solid layers",
            group="paths", minimum=0),
    Setting("bead_model", "choice", "rounded", "bead model",
            "bead cross-section: rounded sides (PrusaSlicer's) or a rectangle",
            group="paths", choices=("rounded", "rectangular")),
    Setting("infill_overlap", "percent", 25.0, "infill overlap",
            "infill reach into the innermost perimeter, percent of a bead spacing",
            group="paths", minimum=0.0, maximum=100.0, open_maximum=True),
    Setting("solid_below_area", "area", 70.0, "solid below area",
            "sparse infill pieces smaller than this are printed solid", group="paths",
            minimum=0.0),
    *(Setting(f"{role}_speed", "speed", default, f"{label} speed", what, group="speeds",
              minimum=0.0, open_minimum=True, derived=derived)
      for role, default, label, what, derived in (
          ("external_perimeter", None, "external perimeter", "outermost perimeter loop",
           "the material's feed (40 mm/s without one)"),
          ("perimeter", None, "perimeter", "inner perimeter loops",
           "the material's feed (40 mm/s without one)"),
          ("small_perimeter", 15.0, "small perimeter",
           "perimeter loops up to 2π·6.5 mm long (PrusaSlicer's rule: small walls need time "
           "to set)", ""),
          ("infill", 60.0, "infill", "sparse infill", ""),
          ("solid_infill", 60.0, "solid infill", "solid infill (skins, small pieces)", ""),
          ("bridge_infill", None, "bridge infill",
           "solid infill laid directly over sparse infill (an internal bridge across its "
           "rows), filled apart when its speed differs, and over nothing (always apart, "
           "across its shortest span)", "the solid infill speed"),
          ("support", 60.0, "support", "support and its interface (--support)", ""),
          ("travel", None, "travel", "moves without deposition",
           "the material's travel feed (150 mm/s without one)"))),
    Setting("jerk", "speed", 10.0, "jerk",
            "largest instant speed change at a corner, for the time estimate and the choice "
            "of plan (the machine file gives the acceleration)", group="speeds",
            minimum=0.0, open_minimum=True),
    Setting("min_layer_time", "time", 5.0, "minimum layer time",
            "layers faster than this are slowed down so they can cool", group="cooling",
            minimum=0.0),
    Setting("min_speed", "speed", 10.0, "minimum print speed",
            "cooling never slows printing below this", group="cooling",
            minimum=0.0, open_minimum=True),
    Setting("alternate", "bool", True, "alternate sub-parts",
            "where sub-parts ready together would be slowed down to cool, lay their layers in "
            "turn instead, the table turning between them, when that is quicker",
            group="cooling", prop="AlternateSubParts"),
    Setting("support", "bool", False, "support",
            "print support under the overhang the plan leaves (none where it leaves none), "
            "in the sub-part's own planar layers", group="support", prop="PrintSupport"),
    Setting("support_spacing", "length", 2.5, "support spacing",
            "gap between support lines, as PrusaSlicer's pattern spacing (its default): "
            "the lines lie a bead spacing farther apart; 0 prints the support solid",
            group="support", minimum=0.0),
    Setting("support_interface_layers", "int", 3, "support interface layers",
            "solid layers on top of the support, under the overhang", group="support",
            minimum=0),
    Setting("support_bottom_interface_layers", "int", -1, "support bottom interface layers",
            "solid layers at the foot of a column that stands on the part (-1: as many as "
            "on top, PrusaSlicer's default); none on the platform", group="support",
            minimum=-1),
    Setting("support_bridges", "bool", False, "support bridges",
            "also support what a bridge spans, from wall to wall (off, as PrusaSlicer's "
            "'Don't support bridges' is on: the bridge is laid over the gap)",
            group="support"),
)

#: Print roles with a `<role>_speed` setting (fields of paths/assemble.Feeds).
SPEED_ROLES = tuple(s.key.removesuffix("_speed") for s in PLAN_SETTINGS
                    if s.group == "speeds" and s.key.endswith("_speed"))
