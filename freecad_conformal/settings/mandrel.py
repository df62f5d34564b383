"""Settings of a build on a rotating mandrel (`mandrel` command; `plan --mandrel` takes the
mapping): unrolled cylindrical layers about the machine's one table rotary axis."""
from __future__ import annotations

from dataclasses import replace

from freecad_conformal.settings.plan import machine_names
from freecad_conformal.settings.schema import Setting

#: METHODS section 5 printed at 2000 mm/min and travelled at 2400 mm/min.
PRINT_FEED = 2000.0
TRAVEL_FEED = 2400.0

#: Mandrel builds have no document object yet: the settings are flags only (prop "").
MAPPING = Setting("mapping", "choice", "rotary", "rotation mapping",
                  "rotary: the A axis in degrees; linear: the rotation driven as Y scaled at "
                  "the first-layer radius, with extrusion and feed compensation",
                  group="mandrel", choices=("rotary", "linear"), prop="")

_SETTINGS: tuple[Setting, ...] = (
    Setting("machine", "machine", "rotary_mandrel", "machine",
            "machine with one table rotary axis (the mandrel), or a .json path",
            group="mandrel", choices=machine_names),
    Setting("tool", "text", "fdm_0p4", "tool", "tool id in the tool library", group="mandrel"),
    Setting("layer", "length", 0.3, "layer height", "layer thickness (radial)",
            group="mandrel", flag="--layer-height", aliases=("--layer",), minimum=0.0,
            open_minimum=True),
    Setting("width", "length", None, "bead width", "bead width", group="mandrel",
            minimum=0.0, open_minimum=True, derived="the tool diameter"),
    Setting("feed", "feed", PRINT_FEED, "print feed", "print speed on the surface",
            group="mandrel", minimum=0.0, open_minimum=True),
    Setting("travel_feed", "feed", TRAVEL_FEED, "travel feed", "travel speed",
            group="mandrel", minimum=0.0, open_minimum=True),
    Setting("angle", "angle", None, "raster angle", "raster angle in the unrolled plane",
            group="mandrel", minimum=-360.0, maximum=360.0,
            derived="along each layer's long axis (the band inclination for a helix)"),
    MAPPING,
    Setting("material", "text", "filament", "material", "material name for the header",
            group="mandrel"),
)

MANDREL_SETTINGS: tuple[Setting, ...] = tuple(replace(s, prop="") for s in _SETTINGS)
