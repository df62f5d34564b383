"""A hybrid plan's steps: deposit layer by layer, mill when a rule says so (paths/hybrid.py)."""
from __future__ import annotations

from typing import Callable, Sequence

import numpy as np

from freecad_conformal.decomposition.subparts import BuildPlan
from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.geometry.face_normals import plane_normal
from freecad_conformal.geometry.holes import Hole
from freecad_conformal.geometry.stock import surface_samples
from freecad_conformal.layers.model import Layer
from freecad_conformal.paths.assemble import PathSettings, plan_paths
from freecad_conformal.paths.hybrid import (DRILL_OVERLAP, SHADOW_STEP, HybridSequence, Session, Shadows, Step,
                                            along, deposit_prism, drill_tool, face_to, facing,
                                            final_drills,
                                            final_finishing, finishing_axes,
                                            finishing_passes, grows_out, layer_bottom,
                                            nominal_paths, session_drills)
from freecad_conformal.paths.ball_finish import ball_passes, finish_faces
from freecad_conformal.paths.milling import MillTool
from freecad_conformal.paths.pencil import pencil_passes


def _flat_walls(shape, layer: Layer, stack: Sequence[Layer], k: int) -> bool:
    """True when the part's walls where the next layer reaches out are planar (the last
    "3+2" finishing passes lie on them), so deposition need not stop there."""
    if k + 1 >= len(stack):
        return True
    beyond = stack[k + 1].region.difference(layer.region)
    if beyond.is_empty:
        return True
    App, Part = import_freecad()
    uv = np.asarray(beyond.representative_point().coords)
    point = stack[k + 1].frame.to_3d(uv, stack[k + 1].section_height)[0]
    vertex = Part.Vertex(App.Vector(*point))
    nearest = min(shape.Faces, key=lambda f: f.distToShape(vertex)[0])
    return plane_normal(nearest) is not None      # B-spline planes too


def _top_along(layer: Layer, normal: np.ndarray) -> float:
    """The highest point of the layer's slab top along `normal`."""
    rings = [np.asarray(p.exterior.coords) for p in layer.region.geoms]
    if not rings:
        return float(layer.top_point @ normal)
    return float(max((layer.to_3d(ring) @ normal).max() for ring in rings))


def _reach(holes: Sequence[Hole], normal: np.ndarray, bottom: float, top: float,
           tools: Sequence[MillTool]) -> float:
    """How far above the first unfinished layer's bottom deposition may go: the finishing
    tool's flutes, or the flutes of a drill cutting a hole along the build in that span."""
    reach = tools[0].flute_length
    for hole in holes:
        if not along(hole, normal):
            continue
        ends = sorted(float(hole.end(w) @ normal) for w in ("low", "high"))
        if ends[1] <= bottom or ends[0] >= top:
            continue
        tool = drill_tool(hole, tools)
        if tool is not None:
            # each cut reaches DRILL_OVERLAP into the one before
            reach = min(reach, tool.flute_length - DRILL_OVERLAP)
    return reach


def _break(stack: Sequence[Layer], first: int, k: int, holes: Sequence[Hole],
           tools: Sequence[MillTool], finished_later: bool, faced: bool = False) -> str:
    """Why milling must come after layer k ('' when deposition may go on); `faced`: a run
    of 3-D layers deposited as planar layers ends at k (paths/hybrid_groups.py)."""
    layer = stack[k]
    if faced:
        return "3-D layers' top"
    if layer.tilted:
        return "3-D layer top"
    if k + 1 == len(stack):
        return "sub-part built"
    upper = stack[k + 1]
    if grows_out(layer, upper) and not finished_later:
        return "wall turns outward"
    normal = layer.top_normal
    bottom = layer_bottom(stack[first])
    top = _top_along(upper, normal)
    if top - bottom > _reach(holes, normal, bottom, top, tools) + 1e-9:
        return "tool reach"
    return ""


def _rest_finishing(part, tools: Sequence[MillTool], directions: Sequence[np.ndarray],
                    holes: Sequence[Hole], notes: list[str]) -> list:
    """Last passes with the V-bit (sharp concave edges) and the ball end mill (curved
    faces the flat end mill leaves stepped), when listed."""
    balls = [t for t in tools if t.ball]
    faces = finish_faces(part, directions, holes) if balls else []
    if not faces and not any(t.tapered for t in tools):
        return []
    points, normals = surface_samples(part)
    passes = pencil_passes(part, tools, points, normals, notes)
    if faces:
        passes += ball_passes(part, faces, balls[0], directions, points, normals, notes)
    return passes


def hybrid_sequence(plan: BuildPlan, layers: dict[int, list[Layer]], settings: PathSettings,
                    holes: Sequence[Hole], tools: Sequence[MillTool], stock: float,
                    d_max: float, progress: Callable[[str], None] | None = None,
                    faces: dict[int, dict] | None = None, part=None) -> HybridSequence:
    """Deposition and milling steps for the whole plan (`tools[0]` finishes the walls and
    faces 3-D layers; every flat tool may cut holes; at the end a V-bit runs along the sharp
    concave edges of `part`, the finished part as placed, and a ball end mill over its
    curved faces). `faces[sub][k]`:
    after layer k, face to the plane (point, normal) what was deposited since layer `first`
    (a GroupedStack's)."""
    faces = faces or {}
    steps: list[Step] = []
    deposits = []
    sessions: list[Session] = []
    notes: list[str] = []
    built: list = []
    normals: list[np.ndarray] = []
    position = None
    count = 0
    for sub in plan.ordered():
        stack = layers.get(sub.index) or []
        if not stack:
            continue
        normals.append(np.asarray(sub.build_direction, dtype=float))
        per_layer = plan_paths(stack, settings, sub.parent is not None, position)
        planes = faces.get(sub.index, {})
        first = 0
        for k, layer in enumerate(stack):
            below = (stack[k - 1].top_point, stack[k - 1].top_normal) if k else (None, None)
            if k - 1 in planes:
                below = planes[k - 1][:2]       # deposited on the face milled there
            paths = per_layer[k]
            if layer.tilted and below[0] is not None:
                paths = nominal_paths(paths, below[0], below[1], d_max)
            steps.append(Step("deposit", paths))
            prism = deposit_prism(layer, below[0], below[1], stock, d_max)
            prism.order = len(sessions)           # milled by this session and later ones
            deposits.append(prism)
            count += 1
            if paths:
                position = paths[-1].points[-1]
            reason = _break(stack, first, k, holes, tools, _flat_walls(sub.shape, layer, stack, k),
                            k in planes)
            if not reason:
                continue
            shadows: dict[tuple, Shadows] = {}

            def shadows_for(normal: np.ndarray, _layer: Layer = layer) -> Shadows:
                key = tuple(np.round(normal, 12))
                if key not in shadows:
                    shadows[key] = Shadows(built, sub.shape, _top_along(_layer, normal), normal)
                return shadows[key]

            step = min(SHADOW_STEP, layer.thickness_min)
            session = Session(sub.index, first, k, reason)
            if k in planes:
                point, normal, start = planes[k]
                run = deposits[len(deposits) - (k - start + 1):]
                session.passes += face_to(run, point, normal, shadows_for(normal), tools[0], step)
            elif layer.tilted and below[0] is not None:
                session.passes += facing(layer, below[0], below[1], d_max, stock,
                                         shadows_for(layer.top_normal), tools[0], step)
            session.passes += finishing_passes(stack[first:k + 1], shadows_for, stock, tools[0], step)
            normal = layer.top_normal
            session.passes += session_drills(holes, normal, layer_bottom(stack[first]),
                                             _top_along(layer, normal), tools)
            for cut in session.passes:
                cut.sweep.order = len(sessions)
            sessions.append(session)
            steps.append(Step("mill", session=session))
            if progress is not None:
                progress(f"sub-part {sub.index}: milling after layer {k} ({reason})")
            first = k + 1
        built.append(sub.shape)
    # the walls along the build directions were finished session by session; faces
    # leaning from all of them get passes along an axis in their plane
    extra = finishing_axes(built, normals, normals[0])[len(normals):] if built else []
    drills = final_finishing(built, extra, tools[0], SHADOW_STEP) if extra else []
    drills += final_drills(holes, normals, tools, notes)
    drills += _rest_finishing(part, tools, normals, holes, notes) if part is not None else []
    if drills:
        if not sessions:
            sessions.append(Session(-1, 0, 0, "holes"))
            steps.append(Step("mill", session=sessions[-1]))
        for cut in drills:
            cut.sweep.order = len(sessions) - 1
        sessions[-1].passes += drills
        sessions[-1].reason += ", last finishing"
    return HybridSequence(steps, deposits, sessions, count, notes)
