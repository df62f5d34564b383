"""The verifier's G-code reader: numbers as LinuxCNC reads them, comments, modal state."""
from __future__ import annotations

import numpy as np
import pytest

from freecad_conformal.errors import PostError
from freecad_conformal.post import samples
from freecad_conformal.post.gcode_reader import read_joints
from freecad_conformal.post.machine import load_machine
from freecad_conformal.post.nearest import nearest_poses
from freecad_conformal.post.program import post_toolpath
from freecad_conformal.post.verify import verify_program

XYZ = ("X", "Y", "Z")


@pytest.mark.parametrize("text, message", [
    ("G0 X0 Y0 Z0\nG1 X1e2\n", r"line 2: 'G1 X1e2' .*exponent"),
    ("G0 X0 Y0 Z0\nG1 X1.5E-3 Y0\n", r"line 2: .*exponent"),
    ("G0 XNaN Y0 Z0\n", r"line 1: 'G0 XNaN Y0 Z0' is not G-code"),
    ("G0 Xinf Y0 Z0\n", "is not G-code"),
    ("G0 X1.2.3 Y0 Z0\n", "is not G-code"),
    ("G0 X- Y0 Z0\n", "is not G-code"),
    ("G0 X0 Y0 Z0 (open comment\n", "unclosed comment"),
    ("G0 X0 Y0 Z0\nG2 X1 Y1 I1\n", "line 2: arcs"),
    ("G91\nG0 X0 Y0 Z0\n", "line 1: relative"),
    ("G0 X0 Y0 Z0\nG92 X5\n", "line 2: G92"),
    ("G1 X0 Y0\n", "first move does not set axis/axes Z"),
    ("G0 X0 Y0 Z0\nG28\nG1 X1\n", "line 3 does not set axis/axes Y, Z"),
    ("M2\n", "no G0/G1 move"),
])
def test_reader_refuses_what_a_controller_would_read_differently(text, message):
    with pytest.raises(PostError, match=message):
        read_joints(text, XYZ)


def test_reader_comments_blanks_and_modal_moves():
    text = ("(tolerance: 0.01 mm, 0.05 deg; 24 segments)\n"      # ';' inside ( ... )
            "G0 X0 Y0 Z0 (a; b) ; c (d\n"                         # '(' inside a ';' comment
            "G92 E0\n"                                            # not the machine's axes
            "G1 X1 Y2 Z3 E0.5 F100\n"
            "X 4 . 5\n"                                           # LinuxCNC allows blanks in numbers
            "G28\n"
            "G0 X7 Y8 Z9\n")
    joints, lines, _ = read_joints(text, XYZ)
    assert joints.tolist() == [[0, 0, 0], [1, 2, 3], [4.5, 2, 3], [7, 8, 9]]
    assert lines.tolist() == [2, 4, 5, 7]


def test_reader_reads_rotary_words_in_degrees():
    joints, _, _ = read_joints("G0 X0 Y0 Z0 A90 C-180\n", ("X", "Y", "Z", "A", "C"))
    assert np.allclose(joints[0, 3:], [np.pi / 2, -np.pi])


def test_nearest_poses_is_exact_against_brute_force():
    rng = np.random.default_rng(3)
    path = np.cumsum(rng.normal(scale=0.3, size=(300, 3)), axis=0)
    path_axes = np.tile([0.0, 0.0, 1.0], (300, 1))
    points = path[rng.integers(0, 299, 500)] + rng.normal(scale=0.2, size=(500, 3))
    axes = np.tile([0.0, 0.0, 1.0], (500, 1))
    distance, _, _ = nearest_poses(points, axes, path, path_axes)
    a, b = path[:-1], path[1:]
    chord = b - a
    t = np.clip(np.einsum("qij,ij->qi", points[:, None] - a, chord) / (chord * chord).sum(1), 0, 1)
    brute = np.linalg.norm(a + t[..., None] * chord - points[:, None], axis=2).min(axis=1)
    assert np.allclose(distance, brute, atol=1e-12)


def test_guessed_matches_give_the_exact_largest_deviation():
    # a replay that follows a wiggly path closely, with a few samples pushed off it: the
    # arc-length guess plus the full search where it matters finds the same maxima as the
    # full search everywhere, and never matches a point better than the full search
    from freecad_conformal.post.nearest import (
        POSE_LEVER, arc_length_guess, nearest_where_it_matters)
    rng = np.random.default_rng(11)
    t = np.linspace(0.0, 20.0, 4000)
    path = np.column_stack([10 * np.cos(t), 10 * np.sin(t), 0.5 * t])
    path_axes = np.column_stack([0.3 * np.cos(t), 0.3 * np.sin(t), np.ones_like(t)])
    path_axes /= np.linalg.norm(path_axes, axis=1)[:, None]
    s = np.sort(rng.uniform(0.0, 20.0, 3000))
    samples_ = np.column_stack([10 * np.cos(s), 10 * np.sin(s), 0.5 * s])
    samples_ += rng.normal(scale=1e-3, size=samples_.shape)
    pushed = rng.choice(len(s), 5, replace=False)
    samples_[pushed] += rng.normal(scale=0.05, size=(5, 3))
    sample_axes = np.column_stack([0.3 * np.cos(s), 0.3 * np.sin(s), np.ones_like(s)])
    sample_axes /= np.linalg.norm(sample_axes, axis=1)[:, None]
    full = nearest_poses(samples_, sample_axes, path, path_axes)
    fast = nearest_where_it_matters(samples_, sample_axes, path, path_axes,
                                    arc_length_guess(samples_, path))
    assert fast[0].max() == full[0].max() and fast[1].max() == full[1].max()
    assert np.argmax(fast[0]) in pushed
    assert np.all(fast[0] + POSE_LEVER * fast[1] >= full[0] + POSE_LEVER * full[1] - 1e-12)


def test_verify_finds_a_program_that_skips_part_of_the_path():
    machine, toolpath = load_machine("trunnion_ac"), samples.tilted_ring()
    text = post_toolpath(toolpath, machine).text
    lines = text.splitlines()
    moves = [i for i, line in enumerate(lines) if line.startswith("G1")]
    cut = lines[:moves[20]] + lines[moves[40]:]                    # 20 blocks missing
    # C still turns the part under the tip, so the shortcut stays near the ring, but not
    # within the tolerance
    assert verify_program("\n".join(cut), machine, toolpath).position > 0.05
