"""The Analysis and Decomposition objects' computations on plain data (objects/work.py runs
them in-process or in a worker): shapes (OCC binary) and values in, shapes, numbers and the axes as
plain lists out."""
from __future__ import annotations

import math

from freecad_conformal.objects.computed import shape_from_bytes, shape_to_bytes


def plain_axes(graphs) -> dict:
    """Nodes and links of every axis graph (one per solid) as lists: points (x, y, z), link
    and break index pairs flattened, node indices counted across the graphs."""
    points: list[tuple[float, float, float]] = []
    links: list[int] = []
    breaks: list[int] = []
    for graph in graphs:
        offset = len(points)
        points += [tuple(float(c) for c in node.point) for node in graph.nodes]
        for link in graph.links:
            pair = [link.start + offset, link.end + offset]
            links += pair
            if link.is_break:
                breaks += pair
    return {"points": points, "links": links, "breaks": breaks}


def compute_analysis(inputs: dict, progress) -> dict:
    """Centroidal axes and candidate splitting faces (OCC binary) of a shape (the same)."""
    import Part

    from freecad_conformal.geometry.centroidal_axis import centroidal_axis
    from freecad_conformal.geometry.concave_edges import concave_edges
    from freecad_conformal.geometry.solids import solids_of
    from freecad_conformal.geometry.splitting_faces import face_candidates

    solids = solids_of(shape_from_bytes(inputs["brep"]), inputs["label"])
    graphs = []
    for k, solid in enumerate(solids):
        progress(0.8 * k / len(solids), f"centroidal axis of solid {k + 1}/{len(solids)}")
        graphs.append(centroidal_axis(solid, method=inputs["method"], step=inputs["step"],
                                      break_angle=math.radians(inputs["break_angle"])))
    progress(0.8, "splitting faces at concave edges")
    faces = [c.region for solid in solids for c in face_candidates(solid, concave_edges(solid))]
    return {"axes": plain_axes(graphs), "faces": len(faces),
            "brep": shape_to_bytes(Part.Compound(faces))}


def compute_decomposition(inputs: dict, progress) -> dict:
    """Sub-parts (their compound in OCC binary), build order, directions and notes."""
    import Part

    from freecad_conformal.jobs.decompose import decompose_with

    progress(0.05, "searching the splits")
    plan = decompose_with(shape_from_bytes(inputs["brep"]), inputs["values"])
    return {"axes": plain_axes(plan.axes), "subparts": len(plan.subparts),
            "order": [int(k) for k in plan.order],
            "directions": [tuple(float(c) for c in s.build_direction) for s in plan.subparts],
            "saved": float(plan.support_area_saved), "notes": list(plan.notes),
            "brep": shape_to_bytes(Part.Compound([s.shape for s in plan.subparts]))}
