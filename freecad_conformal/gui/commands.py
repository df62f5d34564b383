"""FreeCAD GUI commands (ids prefixed Conformal_); each calls the same code as the CLI.

A command gathers the selection, opens a document transaction, creates the parametric object
(freecad_conformal.objects) and opens a task panel for its parameters: OK recomputes and
commits (undoable), Cancel aborts (the object goes away).
"""
from __future__ import annotations

import importlib.util

import FreeCAD
import FreeCADGui

from freecad_conformal.gui.icons import icon
from freecad_conformal.gui.qt import translate
from freecad_conformal.gui.views import show
from freecad_conformal.objects.properties import set_values
from freecad_conformal.settings.sections import SECTIONS_SETTINGS


def _tr(text: str) -> str:
    return translate("Conformal", text)


def selected_with(prop: str) -> list:
    """Selected objects that have property `prop` (Shape, ToolpathFile, GcodeFile, ...)."""
    return [o for o in FreeCADGui.Selection.getSelection() if prop in o.PropertiesList]


def has_solid(obj) -> bool:
    """Whether `obj` is a body with at least one solid (not a Sections or Analysis result,
    whose shapes are wires and faces)."""
    from freecad_conformal.objects.computed import Computed

    if isinstance(getattr(obj, "Proxy", None), Computed) and "SubPartCount" not in obj.PropertiesList:
        return False
    shape = getattr(obj, "Shape", None)
    return shape is not None and not shape.isNull() and bool(shape.Solids)


def selected_solids() -> list:
    """Selected objects holding solids (a face selected on a body selects that body)."""
    return [o for o in FreeCADGui.Selection.getSelection() if has_solid(o)]


def selected_face(kinds: tuple[str, ...] = ()):
    """(object, 'FaceN') of the one selected face (of one of `kinds`, when given), or None."""
    for selection in FreeCADGui.Selection.getSelectionEx():
        faces = [n for n in selection.SubElementNames if n.startswith("Face")]
        if len(faces) == 1 and (not kinds or _face_kind(selection.Object, faces[0]) in kinds):
            return selection.Object, faces[0]
    return None


def _face_kind(obj, name: str) -> str:
    from freecad_conformal.geometry.faces import face_kind

    try:
        return face_kind(obj.Shape.getElement(name))
    except Exception:   # noqa: BLE001 - an odd face is simply not offered
        return ""


class ObjectCommand:
    """Create one object from the selection and edit its parameters in a task panel."""

    NAME = ""              # icon name and transaction label
    MENU = ""
    TIP = ""
    GROUPS: tuple[str, ...] = ()
    NEEDS = "Shape"        # property the selected object must have

    def GetResources(self):  # noqa: N802 - FreeCAD's names
        return {"Pixmap": icon(f"Conformal_{self.NAME}"), "MenuText": _tr(self.MENU),
                "ToolTip": _tr(self.TIP)}

    def sources(self) -> list:
        """Objects the command can work on in the selection."""
        if self.NEEDS == "Shape":
            return selected_solids()
        return selected_with(self.NEEDS)

    def IsActive(self):  # noqa: N802
        return FreeCAD.ActiveDocument is not None and bool(self.sources())

    def create(self, doc, source):
        raise NotImplementedError(f"{type(self).__name__} must create its object")

    def Activated(self):  # noqa: N802
        doc = FreeCAD.ActiveDocument
        source = self.sources()[0]
        doc.openTransaction(f"Conformal {self.NAME}")
        obj = show(self.create(doc, source))
        self.use_face(obj)
        open_panel(obj, self)
        return obj

    def use_face(self, obj) -> None:
        """Take what a selected face says (a direction, an axis) into the new object."""


def open_panel(obj, command) -> None:
    from freecad_conformal.gui.task_panel import ObjectTaskPanel

    FreeCADGui.Control.closeDialog()
    FreeCADGui.Control.showDialog(ObjectTaskPanel(obj, command.GROUPS, _tr(command.MENU),
                                                  icon(f"Conformal_{command.NAME}")))


class SectionsCommand(ObjectCommand):
    NAME, MENU = "Sections", "Sections"
    TIP = "Exact planar or cylindrical sections of the selected body"
    GROUPS = ("Sections",)

    def create(self, doc, source):
        from freecad_conformal.gui import preferences
        from freecad_conformal.objects.sections_feature import create_sections

        obj = create_sections(doc, source)
        obj.LayerHeight = preferences.section_spacing()
        obj.ChordTolerance = preferences.chord_tolerance()
        # cylinders about the part's vertical centre line, out to its far side, cut it;
        # the origin's may miss it altogether
        box = source.Shape.BoundBox
        radius_end = max(obj.RadiusStart.Value, 0.5 * box.DiagonalLength)
        set_values(obj, SECTIONS_SETTINGS, {
            "axis_point": (box.Center.x, box.Center.y, box.ZMin), "radius_end": radius_end,
            "radius_step": max(obj.RadiusStep.Value, radius_end / 50.0)})
        return obj

    def use_face(self, obj) -> None:
        """A selected plane gives the layers' direction (its normal); a selected cylinder
        gives the cylinders' axis, in cylindrical mode."""
        chosen = selected_face(("plane", "cylinder"))
        if chosen is None or chosen[0] != obj.Source:
            return
        face = chosen[0].Shape.getElement(chosen[1])
        if face.Surface.__class__.__name__ == "Cylinder":
            set_values(obj, SECTIONS_SETTINGS, {
                "mode": "cylindrical", "axis_point": tuple(face.Surface.Center),
                "direction": tuple(face.Surface.Axis),
                "radius_end": max(obj.RadiusEnd.Value, obj.Source.Shape.BoundBox.DiagonalLength)})
        else:
            u0, u1, v0, v1 = face.ParameterRange
            normal = face.normalAt(0.5 * (u0 + u1), 0.5 * (v0 + v1)) * -1
            set_values(obj, SECTIONS_SETTINGS, {"direction": tuple(normal)})


class AnalyseCommand(ObjectCommand):
    NAME, MENU = "Analyse", "Analyse part"
    TIP = "Centroidal axis (break links marked) and candidate splitting faces of the selected body"
    GROUPS = ("Analysis",)

    def create(self, doc, source):
        from freecad_conformal.objects.analysis_feature import create_analysis

        return create_analysis(doc, source)


class DecomposeCommand(ObjectCommand):
    NAME, MENU = "Decompose", "Decompose"
    TIP = "Split the selected body into support-free sub-parts and order them"
    GROUPS = ("Decomposition",)

    def create(self, doc, source):
        from freecad_conformal.objects.analysis_feature import create_decomposition

        return create_decomposition(doc, source)


class PlanCommand(ObjectCommand):
    NAME, MENU = "Plan", "Plan job"
    TIP = "Layers, paths and G-code for the selected body (the plan command)"
    GROUPS = ("Job",)

    def create(self, doc, source):
        from freecad_conformal.gui import preferences
        from freecad_conformal.objects.job_feature import create_job

        job = create_job(doc, source, machine=preferences.default_machine())
        job.LayerHeight = preferences.layer_height()
        return job


class FeatureCommand(ObjectCommand):
    NAME, MENU = "Feature", "Conformal feature"
    TIP = "Rods, a shell, a pattern or channels on the selected face"
    GROUPS = ("Feature",)

    #: Face kinds a feature is built on, and the kind a new feature starts as on each.
    FACE_KINDS = {"sphere": "rods", "cylinder": "rods", "cone": "shell", "plane": "pattern",
                  "bspline": "pattern", "torus": "shell"}

    def IsActive(self):  # noqa: N802
        return (FreeCAD.ActiveDocument is not None
                and selected_face(tuple(self.FACE_KINDS)) is not None)

    def Activated(self):  # noqa: N802
        from freecad_conformal.objects.feature_object import create_feature

        doc = FreeCAD.ActiveDocument
        body, face = selected_face(tuple(self.FACE_KINDS))
        doc.openTransaction("Conformal Feature")
        kind = self.FACE_KINDS.get(_face_kind(body, face), "rods")
        obj = show(create_feature(doc, body, face, kind=kind))
        open_panel(obj, self)
        return obj


class FeatureExamplesCommand:
    """METHODS section 1's published test cases as parts with Feature objects."""

    def GetResources(self):  # noqa: N802
        return {"Pixmap": icon("Conformal_FeatureExamples"),
                "MenuText": _tr("Published feature examples"),
                "ToolTip": _tr("A new document with the published UV test cases (flat spiral, "
                               "conical cup, fluidic channels, rods on a sphere, tilted rod) as "
                               "parts with Feature objects, computed in the background")}

    def IsActive(self):  # noqa: N802
        return True

    def Activated(self):  # noqa: N802
        from freecad_conformal.gui.examples import open_examples

        return open_examples()


class PostCommand(ObjectCommand):
    NAME, MENU = "Post", "Post-process"
    TIP = "G-code of the selected job, toolpath or feature for a machine"
    GROUPS = ("Post",)
    NEEDS = "ToolpathFile"

    def create(self, doc, source):
        from freecad_conformal.gui import preferences
        from freecad_conformal.objects.post_feature import create_post

        return create_post(doc, source, machine=preferences.default_machine())


class VerifyCommand(ObjectCommand):
    NAME, MENU = "Verify", "Verify"
    TIP = "Replay the selected program through the machine's kinematics against its toolpath"
    GROUPS = ("Verify",)
    NEEDS = "GcodeFile"

    def create(self, doc, source):
        from freecad_conformal.objects.post_feature import create_verify

        return create_verify(doc, source)


class StreamCommand:
    """Send the selected program to a machine (only with pyserial installed)."""

    def GetResources(self):  # noqa: N802
        return {"Pixmap": icon("Conformal_Stream"), "MenuText": _tr("Stream"),
                "ToolTip": _tr("Send the selected program to a machine over a serial port "
                               "(needs pyserial)")}

    def IsActive(self):  # noqa: N802
        return pyserial_installed() and bool(selected_with("GcodeFile"))

    def Activated(self):  # noqa: N802
        from freecad_conformal.gui.stream_panel import StreamPanel

        FreeCADGui.Control.closeDialog()
        FreeCADGui.Control.showDialog(StreamPanel(selected_with("GcodeFile")[0]))


def pyserial_installed() -> bool:
    return importlib.util.find_spec("serial") is not None


class ProcessPanelCommand:
    """Show the dock panel with the tool library and the DOE tabs."""

    def GetResources(self):  # noqa: N802
        return {"Pixmap": icon("Conformal_ProcessPanel"), "MenuText": _tr("Tools and DOE"),
                "ToolTip": _tr("Show the tool library and design-of-experiments panel")}

    def IsActive(self):  # noqa: N802
        return True

    def Activated(self):  # noqa: N802
        from freecad_conformal.gui.dock import process_panel

        process_panel()


COMMANDS = {
    "Conformal_Analyse": AnalyseCommand,
    "Conformal_Decompose": DecomposeCommand,
    "Conformal_Sections": SectionsCommand,
    "Conformal_Feature": FeatureCommand,
    "Conformal_FeatureExamples": FeatureExamplesCommand,
    "Conformal_Plan": PlanCommand,
    "Conformal_Post": PostCommand,
    "Conformal_Verify": VerifyCommand,
    "Conformal_Stream": StreamCommand,
    "Conformal_ProcessPanel": ProcessPanelCommand,
}


def register_all() -> list[str]:
    """Register every command with FreeCAD; returns their ids in toolbar order."""
    for name, cls in COMMANDS.items():
        FreeCADGui.addCommand(name, cls())
    return list(COMMANDS)
