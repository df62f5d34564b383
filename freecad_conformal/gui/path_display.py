"""What the toolpath view draws, as plain arrays (numpy only, no Coin): one indexed line set
with one colour per move, travel moves dimmed or left out, and optional tool-axis ticks.

Move j goes from point j to point j + 1 and belongs to the segment of point j + 1 (the
neutral toolpath's rule: a point is reached from the previous one as its segment says).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

COLOUR_BY = ("SubPart", "Tool", "Kind")
#: Travel moves are drawn in this light grey whatever the colouring ("dimmed").
TRAVEL_COLOUR = (0.78, 0.78, 0.80)
#: Support is drawn in this dark grey whatever the colouring (the PNG preview's): it
#: breaks away after printing, and a user should tell it from the part.
SUPPORT_COLOUR = (0.47, 0.47, 0.47)
#: Colours of deposit, cure and cut moves when colouring by kind (travel is dimmed).
KIND_COLOURS = {"deposit": (0.93, 0.45, 0.10), "cure": (0.55, 0.25, 0.85),
                "cut": (0.85, 0.10, 0.15)}
#: Distinct colours for sub-parts and tools (cycled); readable on white and on FreeCAD's
#: blue gradient.
PALETTE = np.array([(0.12, 0.47, 0.71), (0.93, 0.45, 0.10), (0.17, 0.63, 0.17),
                    (0.84, 0.15, 0.16), (0.58, 0.40, 0.74), (0.55, 0.34, 0.29),
                    (0.89, 0.47, 0.76), (0.09, 0.75, 0.81), (0.74, 0.74, 0.13)])


@dataclass
class LineSetData:
    """Coordinates, coordIndex (polylines separated by -1) and one colour per drawn move."""

    points: np.ndarray          # (n, 3) float32
    coord_index: np.ndarray     # (m,) int32
    part_colours: np.ndarray    # (moves drawn, 3) float32
    moves: int


def segment_colours(toolpath, colour_by: str, segment_subparts: Sequence[int]) -> np.ndarray:
    """(segments, 3) colours by sub-part, tool id or kind."""
    from freecad_conformal.toolpath import KINDS

    if colour_by == "Kind":
        table = np.array([KIND_COLOURS.get(name, TRAVEL_COLOUR) for name in KINDS])
        return table[np.asarray(toolpath.kind, dtype=int)]
    if colour_by == "Tool":
        keys = np.asarray(toolpath.tool, dtype=int)
    elif colour_by == "SubPart":
        keys = np.asarray(segment_subparts, dtype=int)
        if len(keys) != toolpath.segment_count:
            keys = np.zeros(toolpath.segment_count, dtype=int)
    else:
        raise ValueError(f"colour by must be one of {', '.join(COLOUR_BY)}, got {colour_by!r}")
    return PALETTE[keys % len(PALETTE)]


def line_set(toolpath, colour_by: str = "SubPart", segment_subparts: Sequence[int] = (),
             show_travel: bool = True, support_segments: Sequence[int] = ()) -> LineSetData:
    """The whole toolpath as one line set; runs of hidden moves split the polylines; the
    moves of `support_segments` in `SUPPORT_COLOUR`."""
    from freecad_conformal.toolpath import KINDS

    points = np.asarray(toolpath.points, dtype=np.float32)
    segment_of_move = np.asarray(toolpath.segment_index[1:], dtype=int)
    travel = np.asarray(toolpath.kind, dtype=int)[segment_of_move] == KINDS.index("travel")
    colours = segment_colours(toolpath, colour_by, segment_subparts)[segment_of_move]
    colours[travel] = TRAVEL_COLOUR
    if len(support_segments):
        colours[np.isin(segment_of_move, np.asarray(support_segments, dtype=int))] = SUPPORT_COLOUR
    keep = np.ones(len(segment_of_move), dtype=bool) if show_travel else ~travel
    return LineSetData(points, _polyline_index(keep), colours[keep].astype(np.float32),
                       int(keep.sum()))


def _polyline_index(keep: np.ndarray) -> np.ndarray:
    """coordIndex for the kept moves: each run of kept moves a..b is vertices a..b+1, -1."""
    if not keep.any():
        return np.empty(0, dtype=np.int32)
    edges = np.diff(np.concatenate(([0], keep.astype(np.int8), [0])))
    starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)   # moves [s, e)
    lengths = ends - starts + 2                      # vertices s..e plus the -1
    index = np.full(int(lengths.sum()), -1, dtype=np.int32)
    offsets = np.concatenate(([0], np.cumsum(lengths)[:-1]))
    # vertex k of run r is starts[r] + k, placed at offsets[r] + k
    run_of = np.repeat(np.arange(len(starts)), lengths - 1)
    position = np.arange(int((lengths - 1).sum())) - np.repeat(np.cumsum(lengths - 1) - (lengths - 1),
                                                              lengths - 1)
    index[offsets[run_of] + position] = starts[run_of] + position
    return index


def axis_ticks(toolpath, every: int, length: float) -> np.ndarray:
    """(2k, 3) start/end points of tool-axis ticks at every `every`-th pose."""
    if every < 1 or length <= 0:
        return np.empty((0, 3), dtype=np.float32)
    tips = np.asarray(toolpath.points[::every], dtype=float)
    ends = tips + length * np.asarray(toolpath.axes[::every], dtype=float)
    return np.stack((tips, ends), axis=1).reshape(-1, 3).astype(np.float32)


#: The platform is drawn this much (mm) beyond the toolpath's footprint.
PLATFORM_MARGIN = 5.0
#: Colour of the platform plate (light grey, under translucent paths).
PLATFORM_COLOUR = (0.62, 0.64, 0.68)


def frame_matrices(frame_subparts: Sequence[int], frames: Sequence[float]) -> dict:
    """Sub-part index -> 4x4 motion from the machine frame onto the part (Job.PartFrames)."""
    flat = np.asarray(frames, dtype=float)
    if len(flat) != 12 * len(frame_subparts):
        return {}
    matrices = {}
    for k, index in enumerate(frame_subparts):
        matrix = np.eye(4)
        matrix[:3] = flat[12 * k:12 * k + 12].reshape(3, 4)
        matrices[int(index)] = matrix
    return matrices


def to_part_frame(points: np.ndarray, segment_index: np.ndarray,
                  segment_subparts: Sequence[int], matrices: dict,
                  directions: bool = False) -> np.ndarray:
    """Toolpath points moved from the machine frame onto the part as modelled, each by its
    sub-part's motion (tool axes, `directions`, only turned); points of sub-parts without
    one stay where they are."""
    points = np.asarray(points, dtype=float)
    subparts = np.asarray(segment_subparts, dtype=int)
    if not matrices or len(subparts) == 0:
        return points.copy()
    of_point = subparts[np.asarray(segment_index, dtype=int)]
    moved = points.copy()
    for index, matrix in matrices.items():
        mine = of_point == index
        moved[mine] = points[mine] @ matrix[:3, :3].T + (0.0 if directions else matrix[:3, 3])
    return moved


def platform_corners(points: np.ndarray, margin: float = PLATFORM_MARGIN) -> np.ndarray:
    """(4, 3) corners of the platform under machine-frame toolpath points: at their lowest
    height, their XY footprint grown by `margin`."""
    points = np.asarray(points, dtype=float)
    (x0, y0, z0), (x1, y1, _) = points.min(axis=0), points.max(axis=0)
    x0, y0, x1, y1 = x0 - margin, y0 - margin, x1 + margin, y1 + margin
    return np.array([(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0)])


def platform_plates(points: np.ndarray, segment_index: np.ndarray,
                    segment_subparts: Sequence[int], matrices: dict,
                    margin: float = PLATFORM_MARGIN) -> list[np.ndarray]:
    """(4, 3) platform corners under each group of sub-parts that moves as one (a solid of
    the part: its sub-parts share one motion), carried by that motion onto the part as
    modelled. Machine-frame points; `matrices` as from `frame_matrices` ({} draws one plate
    under everything, in the machine frame)."""
    points = np.asarray(points, dtype=float)
    if not matrices:
        return [platform_corners(points, margin)]
    subparts = np.asarray(segment_subparts, dtype=int)
    of_point = subparts[np.asarray(segment_index, dtype=int)]
    groups: dict[bytes, tuple[np.ndarray, list[int]]] = {}
    for index in np.unique(of_point).tolist():
        matrix = matrices.get(index, np.eye(4))
        key = np.round(matrix, 9).tobytes()          # one solid: one motion, to rounding
        groups.setdefault(key, (matrix, []))[1].append(index)
    plates = []
    for matrix, members in groups.values():
        corners = platform_corners(points[np.isin(of_point, members)], margin)
        plates.append(corners @ matrix[:3, :3].T + matrix[:3, 3])
    return plates
