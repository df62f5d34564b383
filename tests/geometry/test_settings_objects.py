"""The GUI's document objects and the command line read the same settings schema: same
defaults, same checks, and a Job checks its settings before any geometry work."""
from __future__ import annotations

import argparse

import pytest

from freecad_conformal.cli import build_parser
from freecad_conformal.settings.cli import values_from_args
from freecad_conformal.settings.feature import FEATURE_SETTINGS
from freecad_conformal.settings.plan import PLAN_SETTINGS
from freecad_conformal.settings.schema import SettingError, validate


@pytest.fixture
def doc(App):
    document = App.newDocument("SettingsObjects")
    yield document
    App.closeDocument(document.Name)


def _cli(argv) -> argparse.Namespace:
    return build_parser().parse_args(argv)


def test_a_new_job_has_the_plan_commands_defaults(doc, Part):
    from freecad_conformal.objects.job_feature import create_job
    from freecad_conformal.objects.properties import values_from_object

    body = doc.addObject("Part::Feature", "Body")
    body.Shape = Part.makeBox(10, 10, 10)
    job = create_job(doc, body)
    gui = validate(PLAN_SETTINGS, values_from_object(job, PLAN_SETTINGS))
    cli = validate(PLAN_SETTINGS, values_from_args(_cli(["plan", "p.step", "-o", "x"]), PLAN_SETTINGS))
    assert gui == cli
    assert gui["tilt"] is True          # once off in the GUI and on in the CLI


def test_a_new_feature_has_the_feature_commands_defaults(doc, Part):
    from freecad_conformal.objects.feature_object import create_feature
    from freecad_conformal.objects.properties import values_from_object

    body = doc.addObject("Part::Feature", "Ball")
    body.Shape = Part.makeSphere(10)
    feature = create_feature(doc, body, "Face1")
    gui = validate(FEATURE_SETTINGS, values_from_object(feature, FEATURE_SETTINGS))
    cli = validate(FEATURE_SETTINGS, values_from_args(
        _cli(["feature", "p.step", "--face", "Face1", "--kind", "rods", "-o", "x"]),
        FEATURE_SETTINGS))
    assert gui == cli


def test_property_values_reach_the_options_in_their_units(doc, Part):
    from freecad_conformal.objects.feature_object import create_feature
    from freecad_conformal.objects.job_feature import create_job, plan_options
    from freecad_conformal.objects.properties import values_from_object

    body = doc.addObject("Part::Feature", "Body")
    body.Shape = Part.makeSphere(10)
    job = create_job(doc, body)
    job.LayerHeight, job.MinSpeed, job.InfillAngle, job.Root = 0.3, 12.0, "30", "0, 1, 0"
    options = plan_options(job)
    assert options.layers.thickness == pytest.approx(0.3)
    assert options.paths.min_speed == pytest.approx(720.0)           # mm/min
    assert options.paths.fill.angle == pytest.approx(0.5235987755982988)
    assert options.root == (0.0, 1.0, 0.0)
    feature = create_feature(doc, body, "Face1")
    feature.Feed = 2.0                                                # mm/s in FreeCAD
    assert values_from_object(feature, FEATURE_SETTINGS)["feed"] == pytest.approx(120.0)


def test_a_job_refuses_bad_settings_before_decomposing(doc, Part, monkeypatch):
    from freecad_conformal.jobs import plan as jobs_plan
    from freecad_conformal.objects.job_feature import JobFeature, create_job

    def must_not_run(*_args, **_kwargs):
        raise AssertionError("the decomposition ran before the settings were checked")

    monkeypatch.setattr(jobs_plan, "machine_plan", must_not_run)
    body = doc.addObject("Part::Feature", "Body")
    body.Shape = Part.makeBox(10, 10, 10)
    job = create_job(doc, body)
    job.LayerHeight = 0.0
    with pytest.raises(SettingError, match=r"layer height \(--layer-height / LayerHeight\) must be > 0"):
        JobFeature.execute(job.Proxy, job)
    job.LayerHeight = 20.0                                            # thicker than the part
    with pytest.raises(Exception, match="layer"):
        JobFeature.execute(job.Proxy, job)


def test_an_old_job_without_the_new_properties_still_plans_with_defaults(doc, Part):
    from freecad_conformal.objects.job_feature import create_job, plan_options

    body = doc.addObject("Part::Feature", "Body")
    body.Shape = Part.makeBox(10, 10, 10)
    job = create_job(doc, body)
    job.removeProperty("MinLayerTime")
    job.Root = "as placed"                   # the old enumeration's second value
    options = plan_options(job)
    assert options.paths.min_layer_time == 5.0
    assert options.root == (0.0, 0.0, 1.0)


def _new_object_and_command(doc, Part, create, command: str, settings):
    """(checked values of a new object on a box, checked defaults of `command p.step`)."""
    from freecad_conformal.objects.properties import values_from_object

    body = doc.addObject("Part::Feature", "Body")
    body.Shape = Part.makeBox(10, 10, 10)
    made = create(doc, body)
    return (validate(settings, values_from_object(made, settings)),
            validate(settings, values_from_args(_cli([command, "p.step"]), settings)))


def test_a_new_decomposition_has_the_decompose_commands_defaults(doc, Part):
    """The GUI once stopped at 12 sub-parts and the library at 24."""
    from freecad_conformal.objects.analysis_feature import create_decomposition
    from freecad_conformal.settings.decompose import DECOMPOSE_SETTINGS

    gui, cli = _new_object_and_command(doc, Part, create_decomposition, "decompose",
                                       DECOMPOSE_SETTINGS)
    assert gui == cli and gui["max_subparts"] == 24
    assert validate(DECOMPOSE_SETTINGS, values_from_args(
        _cli(["decompose", "p.step", "--no-collision"]), DECOMPOSE_SETTINGS))["collision"] is False


def test_new_sections_have_the_sections_commands_defaults(doc, Part):
    """Sections once had their own properties: a cylinder axis of their own, radii as
    start/end/step where the command took a list."""
    from freecad_conformal.objects.sections_feature import create_sections
    from freecad_conformal.settings.sections import SECTIONS_SETTINGS

    gui, cli = _new_object_and_command(doc, Part, create_sections, "sections",
                                       SECTIONS_SETTINGS)
    assert gui == cli and gui["mode"] == "planar" and gui["layer"] == 1.0


def test_post_and_verify_objects_have_the_commands_defaults(doc, Part):
    """verify's --max-position once defaulted to no check while the Verify object used 0.01."""
    from freecad_conformal.objects.post_feature import create_post, create_verify
    from freecad_conformal.objects.properties import values_from_object
    from freecad_conformal.settings.post import POST_SETTINGS, VERIFY_SETTINGS

    body = doc.addObject("Part::Feature", "Body")
    body.Shape = Part.makeBox(10, 10, 10)
    post = create_post(doc, body)
    verify = create_verify(doc, post)
    gui_post = validate(POST_SETTINGS, values_from_object(post, POST_SETTINGS))
    cli_post = validate(POST_SETTINGS, values_from_args(
        _cli(["post", "t.npz", "-o", "x", "--machine", "trunnion_ac"]), POST_SETTINGS))
    assert gui_post == cli_post
    limits = VERIFY_SETTINGS[1:]
    gui_verify = validate(limits, values_from_object(verify, limits))
    cli_verify = validate(limits, values_from_args(
        _cli(["verify", "p.ngc", "--toolpath", "t.npz", "--machine", "trunnion_ac"]), limits))
    assert gui_verify == cli_verify == {"max_position": 0.01, "max_angle": 0.1}
