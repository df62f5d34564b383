"""Where a Job's toolpath sits on the part: the rigid motion from the part as modelled to the
machine frame the plan builds in, one per sub-part (centred on the platform, turned for the
machine's reach by jobs/placement.py, each solid laid out by decomposition/layout.py).

The motions are measured, not re-derived: the planner moves shapes with copy/rotate/
translate, which keep the order of vertices and edges, so matching points of a shape before
and after a move give the move exactly (Kabsch). The view inverts them to draw the toolpath
on the part.
"""
from __future__ import annotations

import numpy as np

#: Points closer than this (mm) to fitting a rigid motion exactly mean the match was wrong.
FIT_TOLERANCE = 1e-4


def shape_points(shape) -> np.ndarray:
    """Points that move with a shape: vertices, edge midpoints, face centres of mass."""
    points = [tuple(v.Point) for v in shape.Vertexes]
    for edge in shape.Edges:
        first, last = edge.ParameterRange
        points.append(tuple(edge.valueAt(0.5 * (first + last))))
    points += [tuple(face.CenterOfMass) for face in shape.Faces]
    return np.asarray(points, dtype=float)


def rigid_transform(source: np.ndarray, target: np.ndarray) -> np.ndarray:
    """The 4x4 rigid motion taking `source` points onto `target` (same order); ValueError
    when no rigid motion does."""
    if source.shape != target.shape or len(source) < 3:
        raise ValueError(f"cannot match {len(source)} points to {len(target)}")
    a, b = source.mean(axis=0), target.mean(axis=0)
    u, _, vt = np.linalg.svd((source - a).T @ (target - b))
    d = np.sign(np.linalg.det(vt.T @ u.T)) or 1.0
    rotation = vt.T @ np.diag([1.0, 1.0, d]) @ u.T
    matrix = np.eye(4)
    matrix[:3, :3], matrix[:3, 3] = rotation, b - rotation @ a
    error = np.abs(source @ rotation.T + matrix[:3, 3] - target).max()
    if error > FIT_TOLERANCE * max(1.0, np.abs(target).max()):
        raise ValueError(f"the shapes differ by more than a rigid motion ({error:.3g} mm)")
    return matrix


def part_frames(original, placed, before_layout: dict, plan) -> dict:
    """{"frame_subparts": sub-part indices, "frames": 12 numbers each (3x4, row-major)}: the
    motion from the machine frame back to the part as modelled, for each sub-part.
    `before_layout` maps sub-part index -> its shape in the placed part's frame."""
    to_placed = rigid_transform(shape_points(original), shape_points(placed))
    indices, frames = [], []
    for sub in plan.subparts:
        before = before_layout.get(sub.index)
        if before is None:
            continue
        laid = rigid_transform(shape_points(before), shape_points(sub.shape))
        back = np.linalg.inv(laid @ to_placed)
        indices.append(int(sub.index))
        frames += back[:3].ravel().tolist()
    return {"frame_subparts": indices, "frames": frames}


def recording_decompose(record: dict):
    """A decompose function for jobs/plan.machine_plan that keeps the sub-parts' shapes as
    the decomposition made them (before the layout moves them), in `record`."""
    from freecad_conformal.decomposition.decompose import decompose

    def decomposing(shape, **options):
        plan = decompose(shape, **options)
        record.clear()
        record.update({sub.index: sub.shape for sub in plan.subparts})
        return plan
    return decomposing


def store_preview(obj, result: dict) -> None:
    """The part frames into the Job's properties (read by the toolpath view)."""
    obj.PartFrameSubparts = list(result.get("frame_subparts", []))
    obj.PartFrames = list(result.get("frames", []))
