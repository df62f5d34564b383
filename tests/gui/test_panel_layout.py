"""What the task panels show, from the settings schema (no Qt, no FreeCAD)."""
from __future__ import annotations

from freecad_conformal.gui.panel_layout import field_specs, grouped, words
from freecad_conformal.objects.properties import setting_properties
from freecad_conformal.settings.feature import FEATURE_SETTINGS, KINDS
from freecad_conformal.settings.plan import PLAN_SETTINGS


def properties(specs):
    """(name, type, group, tooltip) rows as the panel reads them from an object."""
    return [(name, type_id, group, tip) for type_id, name, group, tip, _ in specs]


def job_fields():
    rows = [("Source", "App::PropertyLink", "Job", "")] + properties(
        setting_properties(PLAN_SETTINGS, "Job"))
    return {f.prop: f for f in field_specs(rows, PLAN_SETTINGS, ("Job",))}


def test_job_labels_are_words_with_units_in_schema_groups():
    fields = job_fields()
    assert "Source" not in fields
    assert fields["LayerHeight"].label == "Layer height [mm]"
    assert fields["Infill"].label == "Infill density [%]"
    assert fields["MinLayerTime"].label == "Minimum layer time [s]"
    assert fields["TiltLayers"].label == "3-D layers"
    assert fields["Machine"].group == "Machine" and fields["Seam"].group == "Paths"
    groups = [name for name, _ in grouped(list(fields.values()))]
    assert groups == ["Machine", "Hybrid", "Layers", "Paths", "Speeds", "Cooling", "Support"]
    assert fields["PrintSupport"].label == "Support" and fields["PrintSupport"].group == "Support"
    assert fields["SupportSpacing"].label == "Support spacing [mm]"
    assert fields["StockAllowance"].label == "Stock allowance [mm]"
    additive, hybrid = {"Process": "additive"}, {"Process": "hybrid"}
    assert not fields["MillTool"].shown(additive) and fields["MillTool"].shown(hybrid)
    assert fields["BridgeInfillSpeed"].label == "Bridge infill speed [mm/s]"
    assert fields["BridgeInfillSpeed"].empty_means == "the solid infill speed"
    assert fields["Tool"].picks == "tools" and fields["Material"].picks == "materials"
    assert fields["Dialect"].picks == "dialects" and fields["Root"].picks == "root"
    assert fields["Material"].empty_means == "the tool's first material"


def test_job_shows_variable_layer_fields_only_in_their_modes():
    fields = job_fields()
    uniform, cusp = {"LayerMode": "uniform"}, {"LayerMode": "cusp"}
    assert not fields["LayerMin"].shown(uniform) and fields["LayerMin"].shown(cusp)
    assert fields["MaxCusp"].shown(cusp) and not fields["MaxVolumeDifference"].shown(cusp)
    assert fields["LayerHeight"].shown(uniform)


def test_feature_shows_the_fields_of_its_kind_and_the_tool():
    rows = [("Kind", "App::PropertyEnumeration", "Feature", "")] + properties(
        setting_properties(FEATURE_SETTINGS, "Feature"))
    fields = field_specs(rows, FEATURE_SETTINGS, ("Feature",))
    assert fields[0].prop == "Kind"          # the kind first: it decides the rest
    for kind in KINDS:
        shown = {f.prop for f in fields if f.shown({"Kind": kind})}
        groups = {f.group for f in fields if f.prop in shown and f.prop != "Kind"}
        placed = {"Placement"} if kind in ("pattern", "channels", "texture") else set()
        assert groups == {"Tool", kind.capitalize()} | placed, kind
    rods = {f.prop for f in fields if f.shown({"Kind": "rods"})}
    assert "RodDiameter" in rods and "PatternText" not in rods and "Channels" not in rods


def test_feature_help_names_the_kind():
    spacing = next(s for s in FEATURE_SETTINGS if s.key == "spacing")
    assert spacing.condition == "kind rods"


def test_sections_fields_come_from_the_schema_with_mode_conditions():
    from freecad_conformal.objects.properties import setting_properties
    from freecad_conformal.settings.sections import SECTIONS_SETTINGS

    rows = [(name, type_id, group, tip)
            for type_id, name, group, tip, _ in setting_properties(SECTIONS_SETTINGS, "Sections")]
    rows.append(("LayerCount", "App::PropertyInteger", "Result", ""))
    fields = {f.prop: f for f in field_specs(rows, SECTIONS_SETTINGS, ("Sections",))}
    assert "LayerCount" not in fields and "Workers" not in fields     # output; CLI only
    assert fields["LayerHeight"].label == "Layer height [mm]"
    assert fields["AxisPoint"].label == "Axis point [mm]"
    assert fields["Direction"].shown({"Mode": "planar"}) and fields["Direction"].shown(
        {"Mode": "cylindrical"})
    assert not fields["AxisPoint"].shown({"Mode": "planar"})
    assert fields["AxisPoint"].shown({"Mode": "cylindrical"})
    assert not fields["LayerHeight"].shown({"Mode": "cylindrical"})
    assert fields["Radii"].empty_means == "radius start to radius end by radius step"


def test_non_schema_objects_get_words_and_units():
    rows = [("Dialect", "App::PropertyString", "Post", ""),
            ("LinearTolerance", "App::PropertyLength", "Post", "")]
    fields = {f.prop: f for f in field_specs(rows, (), ("Post",))}
    assert fields["LinearTolerance"].label == "Linear tolerance [mm]"
    assert fields["Dialect"].picks == "dialects" and fields["Dialect"].when is None
    assert words("AngularTolerance") == "Angular tolerance"
