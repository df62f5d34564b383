"""In FreeCAD: open a real part, run every Conformal command programmatically through its
task panel, check the objects, undo/redo and cancel, errors without dialogs, save/reopen,
and screenshots of the 3D view and of the window with a task panel open."""
import os

import FreeCAD
import FreeCADGui
import Part

import gui_support
from freecad_conformal.gui.colours import face_colours


def run_command(name: str, obj=None, sub: str = ""):
    """Select `obj` (and sub-element), run the command, return its task panel."""
    from freecad_conformal.gui.task_panel import ACTIVE

    print(f"check: {name}", flush=True)
    FreeCADGui.Selection.clearSelection()
    if obj is not None:
        FreeCADGui.Selection.addSelection(obj, sub) if sub else FreeCADGui.Selection.addSelection(obj)
    ACTIVE.clear()
    FreeCADGui.runCommand(name)
    gui_support.settle()
    return ACTIVE.get("panel")


def accept(panel, **fields):
    for name, value in fields.items():
        panel.set_field(name, value)
    panel.accept()              # starts the worker; the panel applies its result
    ok = panel.wait()
    return ok, panel.obj, panel.status


def derived_speed_field(panel, prop: str) -> dict:
    """What an optional speed field shows and holds: unset, typed, emptied by the user."""
    from freecad_conformal.gui.fields import field_value
    from freecad_conformal.gui.qt import QtWidgets

    widget, spec = panel.fields[prop], panel.specs[prop]
    line = widget.findChild(QtWidgets.QLineEdit)
    seen = {"unset": (line.text(), line.placeholderText(), field_value(spec, widget))}
    panel.set_field(prop, 35.0)
    seen["typed"] = (line.text(), field_value(spec, widget))
    widget.setFocus()
    line.selectAll()
    line.del_()                  # the user empties the field and leaves it
    panel.fields["Infill"].setFocus()
    gui_support.settle()
    seen["emptied"] = (line.text(), field_value(spec, widget))
    return seen


def show_only(doc, *objects) -> None:
    for obj in doc.Objects:
        obj.ViewObject.Visibility = obj in objects


def main(params: dict) -> dict:
    gui_support.prepare_main_window()
    FreeCADGui.activateWorkbench("ConformalWorkbench")
    doc = FreeCAD.newDocument("Commands")
    Part.insert(os.path.join(params["parts"], "MODERN_Table_1.brep"), doc.Name)
    body = doc.Objects[0]
    out = {"body": body.Label, "undo_mode": doc.UndoMode}

    ok, analysis, message = accept(run_command("Conformal_Analyse", body))
    out["analysis"] = {"ok": ok, "message": message, "points": len(analysis.AxisPoints),
                       "breaks": analysis.BreakCount, "faces": analysis.SplittingFaceCount}
    show_only(doc, body, analysis)
    body.ViewObject.Transparency = 70
    out["analysis"]["shot"] = gui_support.artifact(params, "analysis_axis.png")
    gui_support.save_3d_view(out["analysis"]["shot"])
    name = analysis.Name
    doc.undo()
    out["undo_removes"] = doc.getObject(name) is None
    doc.redo()
    out["redo_restores"] = doc.getObject(name) is not None

    ok, decomposition, message = accept(run_command("Conformal_Decompose", body),
                                        OverhangAngle=45.0)
    gui_support.settle()
    out["decomposition"] = {"ok": ok, "message": message, "subparts": decomposition.SubPartCount,
                            "order": list(decomposition.BuildOrder),
                            "colours": len(set(face_colours(decomposition.ViewObject)))}
    show_only(doc, decomposition)
    out["decomposition"]["shot"] = gui_support.artifact(params, "decomposition.png")
    gui_support.save_3d_view(out["decomposition"]["shot"])

    ok, sections, message = accept(run_command("Conformal_Sections", body), LayerHeight=5.0)
    out["sections"] = {"ok": ok, "layers": sections.LayerCount}
    panel = run_command("Conformal_Sections", body)
    cancelled = panel.obj.Name
    panel.reject()
    out["cancel_removes"] = doc.getObject(cancelled) is None

    panel = run_command("Conformal_Plan", body)
    for field, value in (("LayerHeight", 1.5), ("BeadWidth", 1.5), ("Infill", 10),
                         ("TiltLayers", False)):
        panel.set_field(field, value)
    out["derived_speed"] = derived_speed_field(panel, "ExternalPerimeterSpeed")
    show_only(doc, body)
    body.ViewObject.Transparency = 0
    out["plan_panel_shot"] = gui_support.artifact(params, "plan_task_panel.png")
    gui_support.grab_main_window(out["plan_panel_shot"])
    ok, job, message = accept(panel)
    out["job"] = {"ok": ok, "message": message, "points": job.PointCount,
                  "subparts": job.SubPartCount, "machine": job.Machine}
    show_only(doc, job)
    job.ViewObject.ColourBy = "SubPart"
    out["job"]["shot"] = gui_support.artifact(params, "job_table_paths.png")
    gui_support.save_3d_view(out["job"]["shot"])

    ok, post, message = accept(run_command("Conformal_Post", job), Machine="trunnion_ac")
    out["post"] = {"ok": ok, "message": message, "blocks": post.BlockCount,
                   "head": open(post.GcodeFile).read(200) if post.GcodeFile else ""}

    sphere = doc.addObject("Part::Sphere", "Dome")
    sphere.Radius = 20.0
    doc.recompute()
    ok, feature, message = accept(run_command("Conformal_Feature", sphere, "Face1"), Kind="rods")
    out["feature"] = {"ok": ok, "message": message, "points": feature.PointCount}
    ok, feature_post, message = accept(run_command("Conformal_Post", feature),
                                       Machine="head_a_table_c")
    out["feature_post"] = {"ok": ok, "message": message, "blocks": feature_post.BlockCount}
    # verify replays every block slowly (about 15 blocks/s): a short toolpath keeps it quick
    from freecad_conformal.objects.toolpath_feature import create_toolpath
    from freecad_conformal.gui.views import show
    from objects_check import helix_toolpath

    probe = show(create_toolpath(doc, helix_toolpath(60, 20), name="Probe"))
    doc.recompute()
    ok, probe_post, message = accept(run_command("Conformal_Post", probe), Machine="trunnion_ac")
    ok, verify, message = accept(run_command("Conformal_Verify", probe_post))
    out["verify"] = {"ok": ok, "message": message, "passed": verify.Passed,
                     "position": verify.PositionDeviation.Value, "report": verify.Report}

    from freecad_conformal.gui import commands

    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(post)
    out["stream_active"] = commands.StreamCommand().IsActive()
    out["pyserial"] = commands.pyserial_installed()
    FreeCADGui.runCommand("Conformal_Stream")
    gui_support.settle()
    stream_panel = FreeCADGui.Control.activeDialog() and _stream_panel()
    if stream_panel is not None:
        stream_panel.baud.setEditText("fast")                   # the schema's check, inline
        out["stream_bad_baud_started"] = stream_panel.start()
        out["stream_bad_baud_message"] = stream_panel.message.text()
        stream_panel.baud.setEditText("115200")
        stream_panel.port.setText(os.path.join(params["tmp"], "no-such-port"))
        out["stream_start"] = stream_panel.start()
        if stream_panel.thread is not None:
            stream_panel.thread.join(30)      # the worker finds the port missing
            stream_panel.poll()
        out["stream_message"] = stream_panel.message.text()
        stream_panel.accept()

    job.LayerHeight = 0.0                 # a bad parameter: marked, reported, no dialog
    doc.recompute()
    out["bad_job_valid"] = job.isValid()
    out["report"] = gui_support.report_view_text()[-8000:]
    job.LayerHeight = 1.5
    doc.recompute()
    out["fixed_job_valid"] = job.isValid()

    path = os.path.join(params["tmp"], "commands.FCStd")
    decomposition_name, verify_name = decomposition.Name, verify.Name
    doc.saveAs(path)
    names = sorted(o.Name for o in doc.Objects)
    FreeCAD.closeDocument(doc.Name)
    reopened = FreeCAD.openDocument(path)
    for obj in reopened.Objects:
        obj.touch()
    reopened.recompute()
    out["reopen"] = {"same_objects": sorted(o.Name for o in reopened.Objects) == names,
                     "invalid": [o.Name for o in reopened.Objects if not o.isValid()],
                     "subparts": reopened.getObject(decomposition_name).SubPartCount,
                     "verify_passed": reopened.getObject(verify_name).Passed}
    return out


def _stream_panel():
    """The stream command's panel: the task view holds it as the dialog's form owner."""
    import gc

    from freecad_conformal.gui.stream_panel import StreamPanel

    panels = [o for o in gc.get_objects() if isinstance(o, StreamPanel)]
    return panels[-1] if panels else None
