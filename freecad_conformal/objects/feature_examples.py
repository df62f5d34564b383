"""The published feature examples (jobs/feature_examples.CASES) as document objects: each
case's part as a Part::Feature and a Feature object on its face with the case's settings,
so a user sees and edits them as any feature of their own."""
from __future__ import annotations

#: Gap between the example parts laid out along X (mm): apart on screen, nothing shared.
SPACING_MM = 20.0


def create_examples(doc) -> list[tuple[object, object]]:
    """(part, feature) per published case, laid out along X; not recomputed (the caller
    computes the features: in place, or in a worker from the GUI)."""
    from freecad_conformal.freecad_env import import_freecad
    from freecad_conformal.jobs.feature_examples import CASES
    from freecad_conformal.objects.feature_object import create_feature
    from freecad_conformal.objects.properties import set_values
    from freecad_conformal.settings.feature import FEATURE_SETTINGS

    App, Part = import_freecad()
    made = []
    x = 0.0
    for case in CASES:
        shape = case.build(App, Part)
        box = shape.BoundBox
        shape.translate(App.Vector(x - box.XMin, -box.Center.y, 0))
        x += box.XLength + SPACING_MM
        part = doc.addObject("Part::Feature", "ExamplePart")
        part.Shape = shape
        part.Label = case.name
        feature = create_feature(doc, part, case.face(shape), kind=case.kind,
                                 name="ExampleFeature")
        feature.Label = f"{case.kind}: {case.name}"
        set_values(feature, FEATURE_SETTINGS, case.settings)
        made.append((part, feature))
    return made
