"""METHODS section 1's test cases, planned end to end, against the published figures."""
from __future__ import annotations

import pytest

from freecad_conformal.jobs import feature_examples as examples


@pytest.mark.slow
def test_published_examples(tmp_path, App):
    results = {e.name: e for e in examples.run(tmp_path)}
    cup = results["inverse conical cup, large tool"].toolpath
    # 2.3 mm wall at 0.4 mm/s (24 mm/min), first layer at half the feed
    assert sorted(set(cup.feed[cup.kind == 2].round(6))) == [12.0, 24.0]
    rods = results["rods on a sphere, small tool"].toolpath
    assert set(rods.feed[rods.kind == 2].round(6)) == {45.0}
    assert "16.0 s curing" in results["12 mm tilted rod"].ours
    assert results["fluidic channels on a cylinder"].toolpath.metadata["tools"] == \
        "T1 uv_large, T2 uv_small"
    assert "0.704·Vmax = 2.50 mm/s" in results["line-curing DOE (speed ∝ power)"].ours
    for name in ("flat_spiral", "inverse_conical_cup", "rods_on_a_sphere", "12_mm_tilted_rod",
                 "fluidic_channels_on_a_cylinder"):
        assert (tmp_path / f"{name}.png").stat().st_size > 10_000
    assert "| 12 mm tilted rod |" in (tmp_path / "examples.md").read_text()


def test_case_settings_round_trip_through_a_feature_object(App):
    """What the GUI sets on the Feature objects is what the CLI plans with."""
    from freecad_conformal.objects.feature_examples import create_examples
    from freecad_conformal.objects.properties import values_from_object
    from freecad_conformal.settings.feature import FEATURE_SETTINGS
    from freecad_conformal.settings.schema import validate

    doc = App.newDocument("ExamplesRoundTrip")
    try:
        made = create_examples(doc)
        assert [p.Label for p, _ in made] == [c.name for c in examples.CASES]
        for (part, feature), case in zip(made, examples.CASES):
            assert feature.Kind == case.kind and feature.Source[0] is part
            ours = validate(FEATURE_SETTINGS, values_from_object(feature, FEATURE_SETTINGS))
            theirs = validate(FEATURE_SETTINGS, dict(case.settings))
            for key in case.settings:
                assert ours[key] == pytest.approx(theirs[key]) if key != "svg" else \
                    ours[key] == theirs[key], (case.name, key)
        boxes = [p.Shape.BoundBox for p, _ in made]
        assert all(a.XMax < b.XMin for a, b in zip(boxes, boxes[1:]))   # laid out apart
    finally:
        App.closeDocument(doc.Name)


def test_svg_setting_takes_path_data_or_names_a_missing_file(App, tmp_path):
    from freecad_conformal.errors import PlanError
    from freecad_conformal.jobs.feature import plan_feature

    import Part
    plate = Part.makeBox(30, 30, 2)
    top = max(plate.Faces, key=lambda f: f.CenterOfMass.z)
    inline = plan_feature(top, "pattern", {"svg": examples.DISC, "width": 0.3, "height": 0.3,
                                           "layer": 0.3}, "disc", part=plate)
    (tmp_path / "disc.txt").write_text(examples.DISC)
    from_file = plan_feature(top, "pattern", {"svg": str(tmp_path / "disc.txt"), "width": 0.3,
                                              "height": 0.3, "layer": 0.3}, "disc", part=plate)
    assert len(inline.points) == len(from_file.points) > 100
    with pytest.raises(PlanError, match="nosuch.svg does not exist"):
        plan_feature(top, "pattern", {"svg": str(tmp_path / "nosuch.svg")}, "disc", part=plate)
