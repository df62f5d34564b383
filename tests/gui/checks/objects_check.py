"""In FreeCAD: Sections, Toolpath and Job objects on real geometry; parameter and body
changes recompute; a failing parameter marks the object; 100,000 poses draw as one line set;
save, close, reopen and recompute. Screenshots of the 3D view."""
import math
import os
import time

import FreeCAD
import FreeCADGui
import numpy as np
import Part

import gui_support


def helix_toolpath(points: int, per_segment: int):
    """A helix of `points` poses: deposit segments with a short travel between them."""
    from freecad_conformal.toolpath import ToolpathBuilder

    builder = ToolpathBuilder(part="helix")
    t = np.linspace(0.0, 40 * math.pi, points)
    xyz = np.column_stack((20 * np.cos(t), 20 * np.sin(t), t / 2))
    axes = np.column_stack((np.cos(t), np.sin(t), np.ones_like(t))) / math.sqrt(2)
    for k, start in enumerate(range(0, points, per_segment)):
        kind = "travel" if k % 10 == 9 else "deposit"
        builder.add_segment(xyz[start:start + per_segment], axes[start:start + per_segment],
                            kind=kind, feed=1200.0, tool=k % 3)
    return builder.build()


def _sections(doc, params) -> dict:
    from freecad_conformal.objects.sections_feature import create_sections
    from freecad_conformal.gui.views import show

    nut = doc.addObject("Part::Feature", "PumpNut")
    nut.Shape = Part.read(os.path.join(params["parts"], "Pump_Nut.brep"))
    planar = show(create_sections(doc, nut, name="NutSections"))
    planar.LayerHeight = 5.0
    sphere = doc.addObject("Part::Sphere", "Ball")
    sphere.Radius = 10.0
    cylindrical = show(create_sections(doc, sphere, mode="cylindrical", name="BallSections"))
    cylindrical.RadiusStart, cylindrical.RadiusEnd, cylindrical.RadiusStep = 2.0, 8.0, 2.0
    doc.recompute()
    out = {"nut_layers_5mm": planar.LayerCount, "nut_valid": planar.isValid(),
           "ball_area_r10": cylindrical.SectionArea.Value}
    planar.LayerHeight = 2.0            # a parameter change
    sphere.Radius = 9.0                 # a change of the source body
    doc.recompute()
    out.update(nut_layers_2mm=planar.LayerCount, ball_area_r9=cylindrical.SectionArea.Value,
               nut_wires=len(planar.Shape.Wires))
    bad = show(create_sections(doc, nut, name="BadSections"))
    bad.LayerHeight = 0.0
    doc.recompute()
    out.update(bad_valid=bad.isValid(), bad_state=list(bad.State),
               bad_status=bad.getStatusString() if hasattr(bad, "getStatusString") else "")
    out["report"] = gui_support.report_view_text()[-3000:]
    gui_support.clear_report_view()
    doc.removeObject(bad.Name)
    doc.recompute()
    return out


def _toolpath(doc, params) -> dict:
    from freecad_conformal.objects.toolpath_feature import create_toolpath
    from freecad_conformal.gui.views import show

    toolpath = helix_toolpath(100_000, 1000)
    started = time.perf_counter()
    obj = show(create_toolpath(doc, toolpath, name="Helix"))
    doc.recompute()
    gui_support.settle()
    seconds = time.perf_counter() - started
    view = obj.ViewObject
    out = {"stats": dict(view.Proxy.stats), "nodes": view.Proxy.scene_counts(),
           "seconds_100k": seconds, "points": obj.PointCount}
    view.ShowTravel = False
    out["moves_without_travel"] = view.Proxy.stats["moves"]
    view.ShowTravel = True
    view.ShowToolAxes = True
    view.AxisEvery = 2000
    view.AxisLength = 8.0
    view.ColourBy = "Tool"
    out["axis_ticks"] = view.Proxy.stats["axis_ticks"]
    for other in doc.Objects:
        other.ViewObject.Visibility = other is obj
    out["shot"] = gui_support.artifact(params, "toolpath_100k.png")
    gui_support.save_3d_view(out["shot"])
    obj.ViewObject.Visibility = False
    return out


def _job(doc, params) -> dict:
    from freecad_conformal.geometry.samples import overhang_bracket
    from freecad_conformal.objects.job_feature import create_job
    from freecad_conformal.gui.views import show

    bracket = doc.addObject("Part::Feature", "Bracket")
    bracket.Shape = overhang_bracket()
    job = show(create_job(doc, bracket, name="BracketJob"))
    job.LayerHeight = 0.5
    job.BeadWidth = 0.8
    job.Infill = 10
    gui_support.clear_report_view()
    started = time.perf_counter()
    doc.recompute()
    out = {"seconds": time.perf_counter() - started, "valid": job.isValid(),
           "report_view": gui_support.report_view_text(),
           "points": job.PointCount, "subparts": job.SubPartCount,
           "distinct_segment_subparts": sorted(set(job.SegmentSubparts)),
           "summary": job.Summary, "gcode_head": open(job.GcodeFile).read(400)
           if job.GcodeFile else ""}
    for other in doc.Objects:
        other.ViewObject.Visibility = other is job
    out["shot"] = gui_support.artifact(params, "job_paths.png")
    gui_support.save_3d_view(out["shot"])
    bracket.ViewObject.Visibility = True
    bracket.ViewObject.Transparency = 85
    out["window_shot"] = gui_support.artifact(params, "job_window.png")
    gui_support.grab_main_window(out["window_shot"])
    return out


def _reopen(doc, params) -> dict:
    path = os.path.join(params["tmp"], "objects.FCStd")
    before = {o.Name: (o.TypeId, getattr(o, "PointCount", None), getattr(o, "LayerCount", None))
              for o in doc.Objects}
    doc.saveAs(path)
    FreeCAD.closeDocument(doc.Name)
    reopened = FreeCAD.openDocument(path)
    after = {o.Name: (o.TypeId, getattr(o, "PointCount", None), getattr(o, "LayerCount", None))
             for o in reopened.Objects}
    helix = reopened.getObject("Helix")
    out = {"before": before, "after_open": after,
           "helix_file_exists": os.path.isfile(helix.ToolpathFile),
           "helix_drawn": dict(helix.ViewObject.Proxy.stats),
           "proxy_classes": {o.Name: type(o.Proxy).__name__ for o in reopened.Objects
                             if hasattr(o, "Proxy")}}
    for obj in reopened.Objects:
        obj.touch()
    reopened.recompute()
    out["after_recompute"] = {o.Name: (o.TypeId, getattr(o, "PointCount", None),
                                       getattr(o, "LayerCount", None)) for o in reopened.Objects}
    out["invalid_after_recompute"] = [o.Name for o in reopened.Objects if not o.isValid()]
    return out


def main(params: dict) -> dict:
    gui_support.prepare_main_window()
    FreeCADGui.activateWorkbench("ConformalWorkbench")
    doc = FreeCAD.newDocument("Objects")
    result = {"sections": _sections(doc, params)}
    for obj in doc.Objects:
        obj.ViewObject.Visibility = obj.Name in ("NutSections", "PumpNut")
    doc.getObject("PumpNut").ViewObject.Transparency = 70
    result["sections"]["shot"] = gui_support.artifact(params, "sections_nut.png")
    gui_support.save_3d_view(result["sections"]["shot"])
    result["toolpath"] = _toolpath(doc, params)
    result["job"] = _job(doc, params)
    result["reopen"] = _reopen(doc, params)
    result["report_at_end"] = gui_support.report_view_text()[-3000:]
    return result
