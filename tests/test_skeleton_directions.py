"""Tests of bone directions <-> positions."""

from __future__ import annotations

import numpy as np
import pytest

from beatlite.skeleton import (
    beat_skeleton,
    directions_to_positions,
    forward_kinematics,
    positions_to_directions,
    skeleton_bones,
)

# a small tree: 0 -> 1 -> 2, 0 -> 3
BONES = np.array([[0, 1], [1, 2], [0, 3]])


def test_directions_by_hand():
    pos = np.array([[[0.0, 0, 0], [0, 2, 0], [3, 2, 0], [0, 0, -5]]])
    dirs = positions_to_directions(pos, BONES)
    assert np.allclose(dirs, [[[0, 1, 0], [1, 0, 0], [0, 0, -1]]])
    back = directions_to_positions(dirs, BONES, lengths=[2.0, 3.0, 5.0], root=[0.0, 0, 0])
    assert np.allclose(back, pos)


def test_round_trip_on_beat_motion():
    skel = beat_skeleton()
    ch = np.random.default_rng(0).uniform(-40, 40, size=(6, skel.n_channels))
    pos = forward_kinematics(skel, ch)
    bones = skeleton_bones(skel)
    assert bones.shape == (74, 2) and np.all(bones[:, 0] < bones[:, 1])
    dirs = positions_to_directions(pos, bones)
    assert dirs.shape == (6, 74, 3) and np.allclose(np.linalg.norm(dirs, axis=-1), 1)
    back = directions_to_positions(dirs, bones, skel.bone_lengths()[1:], pos[:, 0])
    assert np.allclose(back, pos)
    # flat (T, 3B) bone-major input, as HA2G's 126-d vectors
    flat = dirs.reshape(6, -1)
    assert np.allclose(directions_to_positions(flat, bones, skel.bone_lengths()[1:], pos[:, 0]), pos)
    # un-normalised directions are normalised by default
    assert np.allclose(directions_to_positions(3 * dirs, bones, skel.bone_lengths()[1:], pos[:, 0]), pos)


def test_zero_length_bones_and_validation():
    pos = np.zeros((2, 4, 3))
    pos[:, 1] = [0, 1, 0]
    pos[:, 2] = [0, 1, 0]  # bone (1, 2) has zero length
    pos[:, 3] = [1, 0, 0]
    with pytest.raises(ValueError, match=r"zero-length.*\(1, 2\)"):
        positions_to_directions(pos, BONES)
    dirs = positions_to_directions(pos, BONES, allow_zero=True)
    assert np.all(dirs[:, 1] == 0) and np.allclose(dirs[:, 0], [0, 1, 0])
    with pytest.raises(ValueError, match="bones"):
        positions_to_directions(pos, np.array([0, 1]))
    with pytest.raises(ValueError, match="joint 7"):
        positions_to_directions(pos, np.array([[0, 7]]))
    with pytest.raises(ValueError, match=r"\(\.\.\., J, 3\)"):
        positions_to_directions(np.zeros((2, 4, 2)), BONES)
    unit = np.tile([1.0, 0, 0], (2, 3, 1))
    with pytest.raises(ValueError, match="not placed"):
        directions_to_positions(unit, np.array([[1, 2], [0, 1], [0, 3]]), np.ones(3), np.zeros(3))
    with pytest.raises(ValueError, match="lengths"):
        directions_to_positions(unit, BONES, np.ones(2), np.zeros(3))
    with pytest.raises(ValueError, match="root"):
        directions_to_positions(unit, BONES, np.ones(3), np.zeros((3, 3)))
    with pytest.raises(ValueError, match="single root"):
        directions_to_positions(unit, np.array([[0, 1], [2, 3], [4, 5]]), np.ones(3), np.zeros(3))
    with pytest.raises(ValueError, match="zero vectors"):
        directions_to_positions(np.zeros((2, 3, 3)), BONES, np.ones(3), np.zeros(3))
