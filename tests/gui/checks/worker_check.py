"""In FreeCAD: Plan on CrankArm through the task panel while a 100 ms QTimer ticks in the GUI
thread (the worker process must leave it free), then Cancel a second plan half-way, then
the panels' fields per mode and kind, and screenshots of the panel and the job."""
import os
import time

import FreeCAD
import FreeCADGui
import Part

import gui_support
from freecad_conformal.gui.qt import QtCore


def run_command(name, obj, sub=""):
    from freecad_conformal.gui.task_panel import ACTIVE

    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(obj, sub) if sub else FreeCADGui.Selection.addSelection(obj)
    ACTIVE.clear()
    FreeCADGui.runCommand(name)
    gui_support.settle()
    return ACTIVE.get("panel")


class Ticks:
    """A QTimer every 100 ms in the GUI thread; the gaps between its ticks."""

    def __init__(self):
        self.times = []
        self.timer = QtCore.QTimer()
        self.timer.setInterval(100)
        self.timer.timeout.connect(lambda: self.times.append(time.monotonic()))

    def gaps(self, skip=(0.0, 0.0)):
        """Gaps between ticks, leaving out those spanning the `skip` interval."""
        return [b - a for a, b in zip(self.times, self.times[1:])
                if b < skip[0] or a > skip[1]]


def main(params):
    gui_support.prepare_main_window()
    FreeCADGui.activateWorkbench("ConformalWorkbench")
    doc = FreeCAD.newDocument("Worker")
    Part.insert(os.path.join(params["parts"], "CrankArm.brep"), doc.Name)
    body = doc.Objects[0]
    out = {}

    from freecad_conformal.gui import commands

    FreeCADGui.Selection.clearSelection()
    out["plan_active_nothing"] = commands.PlanCommand().IsActive()
    FreeCADGui.Selection.addSelection(body, "Face1")
    out["plan_active_face_of_body"] = commands.PlanCommand().IsActive()

    panel = run_command("Conformal_Plan", body)
    FreeCADGui.ActiveDocument.ActiveView.viewIsometric()
    FreeCADGui.SendMsgToActiveView("ViewFit")
    panel.set_field("LayerHeight", params["layer"])
    panel.set_field("BeadWidth", params["layer"])    # no layer taller than its bead
    out["job_fields_uniform"] = panel.visible_fields()
    panel.set_field("LayerMode", "cusp")
    gui_support.settle()
    out["job_fields_cusp"] = panel.visible_fields()
    panel.set_field("LayerMode", "uniform")
    out["icon_set"] = not panel.form.windowIcon().isNull()
    ticks = Ticks()
    applying = []
    finish = panel._finish

    def timed_finish(outcome):
        applying.append(time.monotonic())
        finish(outcome)
        applying.append(time.monotonic())
    panel._finish = timed_finish
    ticks.timer.start()
    started = time.monotonic()
    panel.accept()
    out["worker_started"] = panel.worker is not None
    time.sleep(0)                                  # the panel's QTimer drives the rest
    shot_taken = False
    shot_window = (0.0, 0.0)
    while panel.worker is not None and time.monotonic() - started < params["timeout"]:
        from freecad_conformal.gui.qt import QtWidgets

        QtWidgets.QApplication.processEvents()
        if not shot_taken and time.monotonic() - started > 3.0:
            out["running_shot"] = gui_support.artifact(params, "plan_running_panel.png")
            shot_window = (time.monotonic(), 0.0)
            gui_support.grab_main_window(out["running_shot"])
            shot_window = (shot_window[0], time.monotonic())
            out["progress_text"] = panel.progress_line.text()
            shot_taken = True
        time.sleep(0.01)
    ticks.timer.stop()
    job = panel.obj
    applied = (applying[0], applying[-1]) if applying else (0.0, 0.0)
    during = [g for a, b, g in zip(ticks.times, ticks.times[1:], ticks.gaps())
              if b < applied[0] and (b < shot_window[0] or a > shot_window[1])]
    gaps = ticks.gaps(shot_window)
    everything = ticks.gaps()
    out["plan"] = {"seconds": time.monotonic() - started, "ticks": len(ticks.times),
                   "max_gap": max(gaps) if gaps else None,
                   "max_gap_while_working": max(during) if during else None,
                   "apply_s": applied[1] - applied[0],
                   "max_gap_with_screenshot": max(everything) if everything else None,
                   "screenshot_s": shot_window[1] - shot_window[0],
                   "gap_times": [round(b - started, 2) for a, b in
                                 zip(ticks.times, ticks.times[1:]) if b - a > 0.3],
                   "gaps_over_half_second": sum(g > 0.5 for g in gaps),
                   "valid": job.isValid(), "points": job.PointCount,
                   "subparts": job.SubPartCount, "status": panel.status,
                   "seconds_estimate": job.EstimatedSeconds}
    out["undo_names"] = doc.UndoNames[:1]
    for obj in doc.Objects:
        obj.ViewObject.Visibility = obj in (job, body)
    body.ViewObject.Transparency = 80
    job.ViewObject.ColourBy = "SubPart"
    FreeCADGui.ActiveDocument.ActiveView.viewIsometric()
    out["job_shot"] = gui_support.artifact(params, "crankarm_job.png")
    gui_support.save_3d_view(out["job_shot"])
    job.ViewObject.Frame = "Machine"
    body.ViewObject.Visibility = False
    out["job_machine_shot"] = gui_support.artifact(params, "crankarm_job_machine.png")
    gui_support.save_3d_view(out["job_machine_shot"])
    job.ViewObject.Frame = "Part"
    out["frames"] = len(job.PartFrameSubparts)

    panel = run_command("Conformal_Plan", body)
    panel.set_field("LayerHeight", params["layer"])
    panel.set_field("BeadWidth", params["layer"])    # no layer taller than its bead
    name = panel.obj.Name
    panel.accept()
    pid = panel.worker.process.pid
    end = time.monotonic() + 2.0
    while time.monotonic() < end:
        QtCore.QCoreApplication.processEvents()
        time.sleep(0.02)
    cancelled = time.monotonic()
    panel.reject()
    out["cancel"] = {"seconds": time.monotonic() - cancelled,
                     "object_removed": doc.getObject(name) is None,
                     "process_gone": not os.path.exists(f"/proc/{pid}") or _zombie(pid)}

    sphere = doc.addObject("Part::Sphere", "Dome")
    sphere.Radius = 20.0
    box = doc.addObject("Part::Box", "Block")
    doc.recompute()
    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(box, "Face1")
    out["feature_on_box_plane"] = commands.FeatureCommand().IsActive()
    panel = run_command("Conformal_Feature", sphere, "Face1")
    out["feature_kind"] = panel.obj.Kind
    out["feature_fields"] = {}
    for kind in ("rods", "shell", "pattern", "channels"):
        panel.set_field("Kind", kind)
        out["feature_fields"][kind] = panel.visible_fields()
    panel.reject()

    sections = run_command("Conformal_Sections", body)
    out["sections_planar"] = sections.visible_fields()
    sections.set_field("Mode", "cylindrical")
    out["sections_cylindrical"] = sections.visible_fields()
    sections.reject()
    FreeCADGui.Selection.clearSelection()
    analysis_ok = run_command("Conformal_Analyse", body)
    analysis_ok.reject()
    return out


def _zombie(pid):
    try:
        with open(f"/proc/{pid}/stat") as handle:
            return handle.read().split()[2] == "Z"
    except OSError:
        return True
