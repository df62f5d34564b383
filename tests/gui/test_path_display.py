"""The toolpath view's arrays (no FreeCAD): per-move colours, hidden travel, axis ticks,
and the sub-part of every segment of a planned job."""
from __future__ import annotations

import numpy as np
import pytest

from freecad_conformal.gui.path_display import (
    KIND_COLOURS, PALETTE, SUPPORT_COLOUR, TRAVEL_COLOUR, _polyline_index, axis_ticks, line_set)
from freecad_conformal.toolpath import ToolpathBuilder


def small_toolpath():
    builder = ToolpathBuilder()
    builder.add_segment([[0, 0, 0], [1, 0, 0]], kind="travel", feed=3000)          # points 0-1
    builder.add_segment([[2, 0, 0], [3, 0, 0], [4, 0, 0]], kind="deposit", feed=600, tool=1)
    builder.add_segment([[4, 1, 0]], kind="travel", feed=3000)                       # point 5
    builder.add_segment([[5, 1, 0], [6, 1, 0]], kind="cure", feed=60, tool=2)        # 6-7
    return builder.build()


def test_polyline_index_splits_at_hidden_moves():
    keep = np.array([True, True, False, False, True, False, True])
    assert _polyline_index(keep).tolist() == [0, 1, 2, -1, 4, 5, -1, 6, 7, -1]
    assert _polyline_index(np.zeros(3, bool)).size == 0


def test_moves_take_the_colour_of_the_segment_they_enter():
    data = line_set(small_toolpath(), "Kind", show_travel=True)
    travel, deposit, cure = TRAVEL_COLOUR, KIND_COLOURS["deposit"], KIND_COLOURS["cure"]
    # moves into points 1..7: travel, deposit x3, travel, cure x2
    expected = [travel, deposit, deposit, deposit, travel, cure, cure]
    np.testing.assert_allclose(data.part_colours, np.array(expected), atol=1e-6)
    assert data.coord_index.tolist() == list(range(8)) + [-1]


def test_hidden_travel_and_colour_by_subpart():
    data = line_set(small_toolpath(), "SubPart", segment_subparts=[0, 0, 1, 1],
                    show_travel=False)
    assert data.moves == 5
    assert data.coord_index.tolist() == [1, 2, 3, 4, -1, 5, 6, 7, -1]
    np.testing.assert_allclose(data.part_colours[-1], PALETTE[1], atol=1e-6)


def test_support_is_drawn_grey_whatever_the_colouring():
    """Support (segment 1 here) is grey in every colouring, so a user tells what breaks
    away from the part; the other moves keep theirs."""
    for colour_by in ("SubPart", "Tool", "Kind"):
        plain = line_set(small_toolpath(), colour_by, [0, 0, 1, 1])
        data = line_set(small_toolpath(), colour_by, [0, 0, 1, 1], support_segments=[1])
        np.testing.assert_allclose(data.part_colours[1:4], [SUPPORT_COLOUR] * 3, atol=1e-6)
        np.testing.assert_allclose(data.part_colours[[0, 4, 5, 6]],
                                   plain.part_colours[[0, 4, 5, 6]], atol=1e-6)


def test_axis_ticks_start_at_the_tip_along_the_axis():
    ticks = axis_ticks(small_toolpath(), every=3, length=2.0)
    assert ticks.shape == (6, 3)
    np.testing.assert_allclose(ticks[1] - ticks[0], [0, 0, 2.0])
    assert axis_ticks(small_toolpath(), every=0, length=2.0).shape == (0, 3)


def test_unknown_colouring_is_an_error():
    with pytest.raises(ValueError, match="colour by"):
        line_set(small_toolpath(), "Feed")


def test_part_frame_moves_each_subparts_points_by_its_motion():
    from freecad_conformal.gui.path_display import frame_matrices, platform_corners, to_part_frame

    turn = np.array([[0, -1, 0, 10], [1, 0, 0, 0], [0, 0, 1, -5]], dtype=float)   # 90° + shift
    matrices = frame_matrices([1], turn.ravel().tolist())
    points = np.array([[1.0, 0, 0], [1.0, 0, 0], [2.0, 3, 4]])
    moved = to_part_frame(points, np.array([0, 1, 1]), [0, 1], matrices)
    assert np.allclose(moved[0], [1, 0, 0])                 # sub-part 0 has no motion
    assert np.allclose(moved[1], [10, 1, -5]) and np.allclose(moved[2], [7, 2, -1])
    assert frame_matrices([1, 2], [0.0] * 12) == {}          # a count mismatch is ignored
    corners = platform_corners(points, margin=1.0)
    assert np.allclose(corners[0], [0, -1, 0]) and np.allclose(corners[2], [3, 4, 0])


def test_tool_axes_are_only_turned_into_the_part_frame():
    from freecad_conformal.gui.path_display import frame_matrices, to_part_frame

    turn = np.array([[0, -1, 0, 10], [1, 0, 0, 0], [0, 0, 1, -5]], dtype=float)
    axes = to_part_frame(np.array([[1.0, 0, 0]]), np.array([0]), [3],
                         frame_matrices([3], turn.ravel().tolist()), directions=True)
    assert np.allclose(axes[0], [0, 1, 0])


def test_each_solid_gets_its_own_plate_under_it_on_the_part():
    """Two solids laid out side by side on the platform, each moved back differently: a
    plate under each, carried by its own motion (it was one plate under the first)."""
    from freecad_conformal.gui.path_display import frame_matrices, platform_plates

    left = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]], dtype=float)
    right = np.array([[1, 0, 0, -100], [0, 1, 0, 0], [0, 0, 1, 7]], dtype=float)  # shifted back
    matrices = frame_matrices([0, 1, 2], np.concatenate([left.ravel(), left.ravel(),
                                                         right.ravel()]).tolist())
    points = np.array([[0.0, 0, 0], [10, 10, 5], [100, 0, 0], [110, 10, 5]])
    segment_index = np.array([0, 1, 2, 2])
    plates = platform_plates(points, segment_index, [0, 1, 2], matrices, margin=0.0)
    assert len(plates) == 2                      # sub-parts 0 and 1 move as one solid
    assert np.allclose(plates[0][0], [0, 0, 0]) and np.allclose(plates[0][2], [10, 10, 0])
    assert np.allclose(plates[1][0], [0, 0, 7]) and np.allclose(plates[1][2], [10, 10, 7])
    machine = platform_plates(points, segment_index, [0, 1, 2], {}, margin=0.0)
    assert len(machine) == 1 and np.allclose(machine[0][2], [110, 10, 0])
