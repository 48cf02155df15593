"""Tests of the TED-Expressive 43-joint mapping, HA2G levels, angle pairs and palm normals."""

from __future__ import annotations

import numpy as np
import pytest

from beatlite.io import read_bvh
from beatlite.skeleton import (
    ANGLE_PAIRS,
    HA2G_LEVELS,
    HEAD_LANDMARK_OFFSETS,
    TED43_FROM_BEAT,
    TED43_JOINTS,
    TED_BONES,
    TED_VECTOR_NAMES,
    beat_skeleton,
    beat_to_ted43,
    euler_to_matrix,
    forward_kinematics,
    global_transforms,
    pair_angles,
    palm_normals,
    positions_to_directions,
)

# docs/reference_code.md#ted-expressive: joint ids and the 42 (parent, child) vectors of TED Expressive, written out.
EXPECTED_BONES = (
    [(0, 1), (1, 2), (1, 3), (2, 4), (4, 6)]
    + [(6, 8), (8, 9), (9, 10), (6, 11), (11, 12), (12, 13), (6, 14), (14, 15), (15, 16)]
    + [(6, 17), (17, 18), (18, 19), (6, 20), (20, 21), (21, 22)]
    + [(3, 5), (5, 7)]
    + [(7, 23), (23, 24), (24, 25), (7, 26), (26, 27), (27, 28), (7, 29), (29, 30), (30, 31)]
    + [(7, 32), (32, 33), (33, 34), (7, 35), (35, 36), (36, 37)]
    + [(1, 38), (38, 39), (38, 40), (39, 41), (40, 42)]
)


def r(a, b):
    return list(range(a, b + 1))


# docs/reference_code.md#ha2g-levels: table of levels
EXPECTED_LEVELS = [
    r(0, 2) + r(37, 41),
    r(0, 3) + [20] + r(37, 41),
    r(0, 4) + [20, 21] + r(37, 41),
    r(0, 5) + [8, 11, 14, 17] + r(20, 22) + [25, 28, 31, 34] + r(37, 41),
    r(0, 6) + [8, 9, 11, 12, 14, 15, 17, 18] + r(20, 23) + [25, 26, 28, 29, 31, 32, 34, 35] + r(37, 41),
    r(0, 41),
]


def test_joint_names_and_bones_follow_ha2g_order():
    assert len(TED43_JOINTS) == 43 and len(set(TED43_JOINTS)) == 43
    assert TED43_JOINTS[:8] == (
        "spine", "neck", "left_shoulder", "right_shoulder", "left_elbow", "right_elbow", "left_wrist", "right_wrist",
    )  # fmt: skip
    assert TED43_JOINTS[8:11] == ("left_index1", "left_index2", "left_index3")
    assert TED43_JOINTS[20] == "left_thumb1" and TED43_JOINTS[23] == "right_index1"
    assert TED43_JOINTS[38:] == ("nose", "right_eye", "left_eye", "right_ear", "left_ear")
    assert list(TED_BONES) == EXPECTED_BONES
    assert len(TED_VECTOR_NAMES) == 44


def test_levels_match_reference_table():
    assert [list(level) for level in HA2G_LEVELS] == EXPECTED_LEVELS
    assert [3 * len(level) for level in HA2G_LEVELS] == [24, 30, 36, 66, 96, 126]


def test_angle_pairs_as_described_in_reference():
    assert len(ANGLE_PAIRS) == 41
    pairs = set(ANGLE_PAIRS)
    # docs/reference_code.md#palm-normals: finger-base spreads, shoulder chains, head chain, forearm x palm normal
    assert {(17, 5), (5, 8), (8, 14), (14, 11), (34, 22), (22, 25), (25, 31), (31, 28)} <= pairs
    assert {(0, 1), (0, 2), (1, 3), (3, 4), (2, 20), (20, 21)} <= pairs
    assert {(0, 37), (37, 38), (37, 39), (38, 40), (39, 41), (4, 42), (21, 43)} <= pairs
    # chains within each finger: consecutive vectors 3k+5 -> 3k+6 -> 3k+7 (left) and 3k+22... (right)
    for base in [5, 8, 11, 14, 17, 22, 25, 28, 31, 34]:
        assert {(base, base + 1), (base + 1, base + 2)} <= pairs
    assert max(max(p) for p in ANGLE_PAIRS) == 43
    assert TED_VECTOR_NAMES[42] == "left_palm_normal"


def test_palm_normals_and_pair_angles_by_hand():
    dirs = np.tile([0.0, 1.0, 0.0], (2, 42, 1))
    dirs[:, 11] = [1.0, 0, 0]  # left wrist->pinky1
    dirs[:, 17] = [0.0, 0, 2.0]  # left wrist->thumb1 (not unit)
    dirs[:, 28] = [0.0, 0, 1.0]  # right wrist->pinky1
    dirs[:, 34] = [1.0, 0, 0]  # right wrist->thumb1
    normals = palm_normals(dirs)
    # x cross z = -y ; z cross x = +y
    assert np.allclose(normals, [[[0, -1, 0], [0, 1, 0]]] * 2)
    ang = pair_angles(dirs)
    assert ang.shape == (2, 41)
    k = ANGLE_PAIRS.index((4, 42))  # left forearm (0,1,0) vs left palm normal (0,-1,0): pi
    assert np.isclose(ang[0, k], np.pi)
    k = ANGLE_PAIRS.index((21, 43))  # right forearm (0,1,0) vs (0,1,0): 0
    assert np.isclose(ang[0, k], 0)
    k = ANGLE_PAIRS.index((14, 11))  # ring base (0,1,0) vs pinky base (1,0,0): pi/2
    assert np.isclose(ang[0, k], np.pi / 2)
    assert np.allclose(palm_normals(dirs.reshape(2, 126)), normals)
    with pytest.raises(ValueError, match=r"\(\.\.\., 42, 3\)"):
        palm_normals(np.zeros((2, 125)))


def test_beat_to_ted43_rest_pose():
    skel = beat_skeleton()
    zeros = np.zeros((1, skel.n_channels))
    ted = beat_to_ted43(skel, zeros)[0]
    pos = forward_kinematics(skel, zeros)[0]
    assert ted.shape == (43, 3)
    for k, name in enumerate(TED43_FROM_BEAT):
        if name is not None:
            assert np.allclose(ted[k], pos[skel.index(name)])
    # in the rest pose the Head frame is the world frame: landmarks = Head + offset
    head = pos[skel.index("Head")]
    for k, name in enumerate(TED43_JOINTS[38:], start=38):
        assert np.allclose(ted[k], head + HEAD_LANDMARK_OFFSETS[name])
    # anatomy: nose in front of the neck, eyes above the nose, right eye/ear at -X
    assert ted[38, 2] > ted[1, 2] + 5 and ted[39, 1] > ted[38, 1] and ted[39, 0] < 0 < ted[40, 0]
    assert ted[41, 0] < ted[39, 0] and ted[3, 0] < 0 < ted[2, 0]
    dirs = positions_to_directions(ted[None], np.array(TED_BONES))
    assert np.all(np.isfinite(dirs))


def test_head_landmarks_turn_with_the_head():
    skel = beat_skeleton()
    ch = np.zeros((1, skel.n_channels))
    ch[0, skel.rotation_channel_indices(skel.index("Head"))] = [
        0.0,
        90.0,
        0.0,
    ]  # turn the head 90 deg about Y
    ted = beat_to_ted43(skel, ch)[0]
    head = forward_kinematics(skel, ch)[0, skel.index("Head")]
    # Ry(90): (x, y, z) -> (z, y, -x); the nose offset (0, 4, 11) becomes (11, 4, 0)
    assert np.allclose(ted[38] - head, euler_to_matrix([0, 90, 0], "XYZ") @ HEAD_LANDMARK_OFFSETS["nose"])
    assert np.allclose(ted[38] - head, [11.0, 4.0, 0.0])


def test_positions_and_rotations_inputs_agree(real_samples):
    motion = read_bvh(real_samples / "beat_skeleton_2_scott_0_1_1_frame0.bvh")
    rots, pos = global_transforms(motion.skeleton, motion.channels)
    a = beat_to_ted43(motion)
    b = beat_to_ted43(pos, rotations=rots, skeleton=motion.skeleton)
    assert np.allclose(a, b)
    # positions only: an estimated head frame, landmarks still near the head
    c = beat_to_ted43(pos)
    assert np.allclose(c[:, :38], a[:, :38])
    assert np.all(np.linalg.norm(c[:, 38:] - a[:, 38:], axis=-1) < 12)


def test_beat_to_ted43_validation():
    with pytest.raises(ValueError, match="channels"):
        beat_to_ted43(beat_skeleton())
    with pytest.raises(ValueError, match=r"\(T, 75, 3\)"):
        beat_to_ted43(np.zeros((2, 74, 3)))
    with pytest.raises(ValueError, match="rotations"):
        beat_to_ted43(np.zeros((2, 75, 3)), rotations=np.zeros((2, 75, 3)))
