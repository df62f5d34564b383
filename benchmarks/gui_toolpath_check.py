"""Runs inside the FreeCAD GUI (see gui_toolpath.py): draw a toolpath as our one line set and
as the peer layout (one Coin separator + line set per segment), build and render both."""
import time

import FreeCAD
import FreeCADGui

import gui_support


def _peer_root(toolpath):
    """The layout to avoid: one node group per segment."""
    from pivy import coin

    root = coin.SoSeparator()
    starts = toolpath.segment_starts
    for k in range(toolpath.segment_count):
        points = toolpath.points[max(starts[k] - 1, 0):starts[k + 1]]
        group, coords, colour, lines = (coin.SoSeparator(), coin.SoCoordinate3(),
                                        coin.SoBaseColor(), coin.SoLineSet())
        colour.rgb.setValue(0.9, 0.45, 0.1)
        coords.point.setValues(0, len(points), points.tolist())
        lines.numVertices.setValue(len(points))
        for node in (coords, colour, lines):
            group.addChild(node)
        root.addChild(group)
    return root


#: Offscreen renders per layout; the fastest counts (the first one also warms caches).
RENDERS = 4


def _render_seconds(path: str) -> float:
    gui_support.save_3d_view(path, 800, 600)     # fit the view once
    times = []
    for _ in range(RENDERS):
        started = time.perf_counter()
        FreeCADGui.ActiveDocument.ActiveView.saveImage(path, 800, 600, "White")
        times.append(time.perf_counter() - started)
    return min(times)


def main(params: dict) -> dict:
    from objects_check import helix_toolpath
    from freecad_conformal.objects.toolpath_feature import create_toolpath
    from freecad_conformal.gui.views import show

    results = []
    for points, per_segment in params["cases"]:
        toolpath = helix_toolpath(points, per_segment)
        doc = FreeCAD.newDocument("Bench")
        obj = show(create_toolpath(doc, toolpath))
        started = time.perf_counter()     # the view's own work: read the file, colour, fill
        obj.ViewObject.Proxy.redraw(obj.ViewObject)
        ours_build = time.perf_counter() - started
        ours_render = _render_seconds(gui_support.artifact(params, "bench_ours.png"))
        obj.ViewObject.Visibility = False
        started = time.perf_counter()
        root = _peer_root(toolpath)
        view = FreeCADGui.ActiveDocument.ActiveView
        view.getSceneGraph().addChild(root)
        peer_build = time.perf_counter() - started
        peer_render = _render_seconds(gui_support.artifact(params, "bench_peer.png"))
        view.getSceneGraph().removeChild(root)
        FreeCAD.closeDocument(doc.Name)
        results.append({"points": points, "segments": toolpath.segment_count,
                        "ours_build": ours_build, "ours_render": ours_render,
                        "peer_build": peer_build, "peer_render": peer_render})
    return {"results": results}
