"""The settings schema: one definition per setting, the flags and checks made from it."""
from __future__ import annotations

import argparse

import pytest

from freecad_conformal.settings.cli import add_arguments, values_from_args
from freecad_conformal.settings.feature import FEATURE_SETTINGS
from freecad_conformal.settings.mandrel import MANDREL_SETTINGS
from freecad_conformal.settings.plan import PLAN_SETTINGS
from freecad_conformal.settings.sections import SECTIONS_SETTINGS
from freecad_conformal.settings.stream import STREAM_SETTINGS
from freecad_conformal.settings.schema import (
    Setting, SettingError, as_json, defaults, validate)

ALL = PLAN_SETTINGS + FEATURE_SETTINGS


def _parse(settings, argv):
    parser = argparse.ArgumentParser()
    add_arguments(parser, settings)
    return values_from_args(parser.parse_args(argv), settings)


@pytest.mark.parametrize("settings", [PLAN_SETTINGS, FEATURE_SETTINGS, SECTIONS_SETTINGS,
                                      MANDREL_SETTINGS, STREAM_SETTINGS])
def test_every_default_passes_its_own_check(settings):
    assert validate(settings, {}) == validate(settings, defaults(settings))


@pytest.mark.parametrize("settings", [PLAN_SETTINGS, FEATURE_SETTINGS, SECTIONS_SETTINGS,
                                      MANDREL_SETTINGS])
def test_keys_flags_and_properties_are_unique(settings):
    for name in ("key", "cli_flag", "property_name"):
        values = [getattr(s, name) for s in settings if getattr(s, name)]
        assert len(values) == len(set(values)), name


@pytest.mark.parametrize("settings", [PLAN_SETTINGS, FEATURE_SETTINGS, SECTIONS_SETTINGS,
                                      MANDREL_SETTINGS])
def test_no_flags_gives_the_schema_defaults(settings):
    assert validate(settings, _parse(settings, [])) == validate(settings, {})


def test_flags_reach_their_settings_and_old_spellings_still_work():
    values = validate(PLAN_SETTINGS, _parse(PLAN_SETTINGS, [
        "--layer", "0.3", "--no-tilt", "--infill", "35", "--root", "0,1,0", "--seam", "nearest"]))
    assert values["layer_height"] == 0.3 and values["tilt"] is False
    assert values["infill"] == 35.0 and values["root"] == (0.0, 1.0, 0.0)
    assert values["seam"] == "nearest"
    assert validate(PLAN_SETTINGS, _parse(PLAN_SETTINGS, ["--layer-height", "0.1"]))[
        "layer_height"] == 0.1


def test_numbers_may_carry_their_own_unit():
    """A shop's script types 0.2mm or 200um as the task panel's fields take it: a number
    with a unit is converted to the flag's unit; a plain number is in that unit."""
    values = validate(PLAN_SETTINGS, _parse(PLAN_SETTINGS, [
        "--layer-height", "200um", "--infill-angle", "0.5 rad", "--travel-speed", "7.8m/min",
        "--min-layer-time", "0.1min", "--solid-below-area", "0.7cm^2", "--infill", "35%",
        "--bead-width", "0.45"]))
    assert values["layer_height"] == pytest.approx(0.2)
    assert values["infill_angle"] == pytest.approx(28.64788975654116)
    assert values["travel_speed"] == pytest.approx(130.0)
    assert values["min_layer_time"] == pytest.approx(6.0)
    assert values["solid_below_area"] == pytest.approx(70.0)
    assert values["infill"] == 35.0 and values["bead_width"] == 0.45


def test_length_lists_and_points_may_carry_units_per_element():
    """The radii, heights and axis point are text in the task panel and on the command
    line alike: each element may carry its unit; a plain number is in mm."""
    values = validate(SECTIONS_SETTINGS, {"radii": "5mm, 0.6cm,7", "heights": "1, 2.5 mm",
                                          "axis_point": "0, 1cm, 2000um"})
    assert values["radii"] == pytest.approx((5.0, 6.0, 7.0))
    assert values["heights"] == pytest.approx((1.0, 2.5))
    assert values["axis_point"] == pytest.approx((0.0, 10.0, 2.0))
    for wrong in ("5mm, 2s", "5mm, 2 parsecs"):
        with pytest.raises(SettingError, match=r"radii .* must be numbers a,b,c in mm \(or each "
                                               r"with its unit\), got '5mm, 2"):
            validate(SECTIONS_SETTINGS, {"radii": wrong})
    with pytest.raises(SettingError, match="must be numbers a,b,c, got '1, 2mm'"):
        validate(FEATURE_SETTINGS, {"at": "1, 2mm"})     # (u, v) parameters: no unit


@pytest.mark.parametrize("argv, words", [
    (["--layer-height", "0.2s"], ["--layer-height", "'0.2s'", "another kind", "length in mm",
                                  "0.2mm"]),
    (["--layer-height", "0.2 furlongs"], ["'0.2 furlongs'", "not a quantity"]),
    (["--travel-speed", "130mm"], ["another kind", "speed in mm/s"]),
    (["--infill", "20 pct"], ["'20 pct'", "not a percentage"]),
])
def test_a_value_with_a_wrong_unit_is_refused_naming_the_flag(argv, words, capsys):
    with pytest.raises(SystemExit):
        _parse(PLAN_SETTINGS, argv)
    message = capsys.readouterr().err
    assert all(word in message for word in words), message


@pytest.mark.parametrize("argv, words", [
    (["--layer-height", "0"], ["layer height", "--layer-height", "LayerHeight", "> 0", "got 0"]),
    (["--infill", "120"], ["infill density", "--infill", "<= 100", "got 120"]),
    (["--infill-overlap", "100"], ["infill overlap", "< 100"]),
    (["--perimeters", "-1"], ["perimeters", ">= 0", "got -1"]),
    (["--root", "0,0,0"], ["root direction", "--root", "'0,0,0'"]),
    (["--root", "up"], ["root direction", "'up'"]),
    (["--layer-height", "nan"], ["layer height", "finite"]),
])
def test_bad_values_are_refused_naming_the_setting_and_the_value(argv, words):
    with pytest.raises(SettingError) as caught:
        validate(PLAN_SETTINGS, _parse(PLAN_SETTINGS, argv))
    for word in words:
        assert word in str(caught.value)


def test_unknown_keys_and_wrong_types_are_refused():
    with pytest.raises(SettingError, match="unknown setting.*layer_hieght"):
        validate(PLAN_SETTINGS, {"layer_hieght": 0.2})
    with pytest.raises(SettingError, match="whole number"):
        validate(PLAN_SETTINGS, {"perimeters": 2.5})
    with pytest.raises(SettingError, match="true or false"):
        validate(PLAN_SETTINGS, {"tilt": "yes"})
    with pytest.raises(SettingError, match="one of uniform, adaptive, cusp"):
        validate(PLAN_SETTINGS, {"layer_mode": "fast"})


def test_directions_and_number_lists_read_text_and_sequences():
    root = next(s for s in PLAN_SETTINGS if s.key == "root")
    assert root.check("auto") == "auto"
    assert root.check("as placed") == (0.0, 0.0, 1.0)
    assert root.check(" 1, 0 ,0 ") == (1.0, 0.0, 0.0)
    assert root.check([0, 0, -1]) == (0.0, 0.0, -1.0)
    profile = next(s for s in FEATURE_SETTINGS if s.key == "diameter_profile")
    assert profile.check("1.2, 1.0,0.8") == (1.2, 1.0, 0.8)
    with pytest.raises(SettingError, match="numbers"):
        profile.check("1.2, wide")


def test_plan_options_carry_the_values(monkeypatch):
    from freecad_conformal.jobs.options import plan_options

    options = plan_options({"layer_height": 0.3, "infill": 40, "infill_angle": 45,
                            "min_speed": 12, "decompose": False, "solid_layers": 4})
    assert options.layers.thickness == 0.3
    assert options.paths.fill.density == pytest.approx(0.4)
    assert options.paths.fill.angle == pytest.approx(0.7853981633974483)
    assert options.paths.min_speed == pytest.approx(12 * 60)      # mm/s in, mm/min inside
    assert options.paths.top_layers == options.paths.bottom_layers == 4
    assert options.decompose is False
    assert options.settings["layer_height"] == 0.3


def test_json_report_names_units_and_derived_values():
    report = as_json(PLAN_SETTINGS, validate(PLAN_SETTINGS, {}))
    assert report["layer_height"] == {"value": 0.2, "unit": "mm"}
    assert report["bead_width"]["derived"] == "the material's width"
    assert report["root"] == {"value": "auto"}


def test_a_setting_of_unknown_kind_is_a_programming_error():
    with pytest.raises(ValueError, match="unknown kind"):
        Setting("x", "colour", None, "x", "x")


def test_every_setting_says_what_it_is():
    for setting in ALL:
        assert setting.label and setting.help, setting.key
        if setting.optional:
            assert setting.derived, f"{setting.key}: what does leaving it unset mean?"


def test_settings_that_apply_to_one_mode_name_a_real_setting_and_value():
    by_key = {s.key: s for s in PLAN_SETTINGS}
    conditional = [s for s in PLAN_SETTINGS if s.only_when]
    assert {s.key for s in conditional} >= {"layer_min", "layer_max", "max_cusp"}
    for setting in conditional:
        key, values = setting.only_when
        assert set(values) <= set(by_key[key].allowed()), setting.key
    parser = argparse.ArgumentParser()
    add_arguments(parser, PLAN_SETTINGS)
    assert "only with layer mode cusp" in " ".join(parser.format_help().split())


def test_points_and_length_lists_are_checked_per_element():
    values = validate(SECTIONS_SETTINGS, {"axis_point": "1, 2, 0", "radii": "2.5; 5"})
    assert values["axis_point"] == (1.0, 2.0, 0.0) and values["radii"] == (2.5, 5.0)
    with pytest.raises(SettingError, match=r"axis point .*must be a point x,y,z, got '1,2'"):
        validate(SECTIONS_SETTINGS, {"axis_point": "1,2"})
    with pytest.raises(SettingError, match=r"radii .*must be > 0 mm, got 0 mm"):
        validate(SECTIONS_SETTINGS, {"radii": "2, 0"})


def test_section_radii_from_a_list_or_start_end_step():
    from freecad_conformal.settings.sections import section_radii

    assert section_radii(validate(SECTIONS_SETTINGS, {"radii": "3, 1"})) == (3.0, 1.0)
    stepped = validate(SECTIONS_SETTINGS, {"radius_start": 1, "radius_end": 2.0000000001,
                                           "radius_step": 0.5})
    assert section_radii(stepped) == (1.0, 1.5, 2.0)
    with pytest.raises(SettingError, match=r"last radius .* 1 mm is below the first radius"):
        section_radii(validate(SECTIONS_SETTINGS, {"radius_start": 3, "radius_end": 1}))
