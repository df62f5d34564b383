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


def _tr(text: str) -> str:
    return translate("Conformal", text)


def selected_with(prop: str) -> list:
    """Selected objects that have property `prop` (Shape, ToolpathFile, GcodeFile, ...)."""
    return [o for o in FreeCADGui.Selection.getSelection() if prop in o.PropertiesList]


def selected_face():
    """(object, 'FaceN') of the one selected face, or None."""
    for selection in FreeCADGui.Selection.getSelectionEx():
        faces = [n for n in selection.SubElementNames if n.startswith("Face")]
        if len(faces) == 1:
            return selection.Object, faces[0]
    return None


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

    def IsActive(self):  # noqa: N802
        return FreeCAD.ActiveDocument is not None and bool(selected_with(self.NEEDS))

    def create(self, doc, source):
        raise NotImplementedError(f"{type(self).__name__} must create its object")

    def Activated(self):  # noqa: N802
        from freecad_conformal.gui.task_panel import ObjectTaskPanel

        doc = FreeCAD.ActiveDocument
        source = selected_with(self.NEEDS)[0]
        doc.openTransaction(f"Conformal {self.NAME}")
        obj = show(self.create(doc, source))
        FreeCADGui.Control.closeDialog()
        FreeCADGui.Control.showDialog(ObjectTaskPanel(obj, self.GROUPS, _tr(self.MENU)))
        return obj


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
        return obj


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

    def IsActive(self):  # noqa: N802
        return FreeCAD.ActiveDocument is not None and selected_face() is not None

    def Activated(self):  # noqa: N802
        from freecad_conformal.gui.task_panel import ObjectTaskPanel
        from freecad_conformal.objects.feature_object import create_feature

        doc = FreeCAD.ActiveDocument
        body, face = selected_face()
        doc.openTransaction("Conformal Feature")
        obj = show(create_feature(doc, body, face))
        FreeCADGui.Control.closeDialog()
        FreeCADGui.Control.showDialog(ObjectTaskPanel(obj, self.GROUPS, _tr(self.MENU)))
        return obj


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
