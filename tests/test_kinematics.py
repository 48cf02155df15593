"""Tests of forward kinematics: hand-computed chains, scipy as an oracle, and real BVH files."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from beatlite.io import read_bvh
from beatlite.skeleton import (
    Skeleton,
    beat_skeleton,
    forward_kinematics,
    global_transforms,
    local_rotations,
    rest_pose,
)
from beatlite.skeleton import kinematics as kin

XYZ_ROT = ("Xrotation", "Yrotation", "Zrotation")
ZXY_ROT = ("Zrotation", "Xrotation", "Yrotation")
POS = ("Xposition", "Yposition", "Zposition")


def arm(channels_per_joint=(POS + XYZ_ROT, XYZ_ROT, XYZ_ROT), end_site=True) -> Skeleton:
    """Shoulder (root) -> elbow 10 cm along +x -> wrist 8 cm along +x; End Site 2 cm along +x."""
    return Skeleton(
        names=("Shoulder", "Elbow", "Wrist"),
        parents=np.array([-1, 0, 1]),
        offsets=np.array([[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [8.0, 0.0, 0.0]]),
        channels=channels_per_joint,
        end_sites={2: np.array([2.0, 0.0, 0.0])} if end_site else {},
    )


def naive_fk(skel: Skeleton, channels: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Independent reference: scipy Euler matrices and a frame-by-frame, joint-by-joint chain."""
    n_frames = channels.shape[0]
    rots = np.zeros((n_frames, skel.n_joints, 3, 3))
    pos = np.zeros((n_frames, skel.n_joints, 3))
    for t in range(n_frames):
        for j in range(skel.n_joints):
            order = "".join(c[0] for c in skel.channels[j] if c.endswith("rotation"))
            start = int(sum(len(c) for c in skel.channels[:j]))
            vals = dict(zip(skel.channels[j], channels[t, start : start + len(skel.channels[j])]))
            local = np.eye(3)
            if order:
                angles = [vals[f"{a}rotation"] for a in order]
                local = Rotation.from_euler(order, angles, degrees=True).as_matrix()
            p = skel.parents[j]
            # "add": OFFSET + position channels, except a root with position channels (absolute)
            root_channels = p < 0 and any(c.endswith("position") for c in skel.channels[j])
            base = np.zeros(3) if root_channels else skel.offsets[j]
            trans = base + np.array([vals.get(f"{a}position", 0.0) for a in "XYZ"])
            if p < 0:
                rots[t, j], pos[t, j] = local, trans
            else:
                rots[t, j] = rots[t, p] @ local
                pos[t, j] = pos[t, p] + rots[t, p] @ trans
    return rots, pos


# ------------------------------------------------------------------- hand-computed cases
def test_rest_pose_is_summed_offsets():
    skel = arm()
    # (0,0,0); (0,0,0)+(10,0,0); (10,0,0)+(8,0,0); End Site (18,0,0)+(2,0,0)
    assert np.allclose(rest_pose(skel), [[0, 0, 0], [10, 0, 0], [18, 0, 0]])
    assert np.allclose(rest_pose(skel, end_sites=True)[-1], [20, 0, 0])
    zeros = np.zeros((4, skel.n_channels))
    assert np.allclose(forward_kinematics(skel, zeros), rest_pose(skel))
    beat = beat_skeleton()
    fk = forward_kinematics(beat, np.zeros((2, beat.n_channels)), end_sites=True)
    assert np.allclose(fk, rest_pose(beat, end_sites=True))


def test_90_degree_elbow_bend_by_hand():
    skel = arm()
    ch = np.zeros((1, skel.n_channels))
    ch[0, 6 + 2] = 90.0  # Elbow Zrotation (channels: 6 root, then Elbow X Y Z)
    pos = forward_kinematics(skel, ch, end_sites=True)[0]
    # elbow stays at (10,0,0); the forearm (8,0,0) is turned by Rz(90) into (0,8,0)
    assert np.allclose(pos[:3], [[0, 0, 0], [10, 0, 0], [10, 8, 0]])
    # End Site (2,0,0) in the wrist frame, which inherits the elbow rotation: (10, 10, 0)
    assert np.allclose(pos[3], [10, 10, 0])


def test_root_translation_and_rotation_by_hand():
    skel = arm()
    ch = np.zeros((1, skel.n_channels))
    ch[0, :3] = [1.0, 2.0, 3.0]  # root position
    ch[0, 4] = 90.0  # root Yrotation: Ry(90) maps +x to -z
    pos = forward_kinematics(skel, ch)[0]
    assert np.allclose(pos, [[1, 2, 3], [1, 2, -7], [1, 2, -15]])


def test_zxy_channel_order_against_scipy():
    skel = arm((POS + ZXY_ROT, ZXY_ROT, ZXY_ROT))
    rng = np.random.default_rng(7)
    ch = rng.uniform(-180, 180, size=(20, skel.n_channels))
    rots, pos = global_transforms(skel, ch)
    # oracle written out for this chain: R0 = Rzxy(root), R1 = R0 Rzxy(elbow), wrist = elbow + R1 (8,0,0)
    r0 = Rotation.from_euler("ZXY", ch[:, 3:6], degrees=True).as_matrix()
    r1 = r0 @ Rotation.from_euler("ZXY", ch[:, 6:9], degrees=True).as_matrix()
    elbow = ch[:, :3] + r0 @ np.array([10.0, 0, 0])
    wrist = elbow + r1 @ np.array([8.0, 0, 0])
    assert np.allclose(pos[:, 1], elbow) and np.allclose(pos[:, 2], wrist)
    assert np.allclose(rots[:, 1], r1)


def test_mixed_orders_and_channel_positions_against_naive_reference():
    # every joint its own order, the root with rotations before positions
    skel = Skeleton(
        names=("A", "B", "C", "D"),
        parents=np.array([-1, 0, 1, 1]),
        offsets=np.array([[1.0, 2.0, 3.0], [0.0, 5.0, 0.0], [4.0, 0.0, 1.0], [-3.0, 1.0, 0.0]]),
        channels=(
            ("Yrotation", "Xrotation", "Zrotation", "Xposition", "Yposition", "Zposition"),
            ("Xrotation", "Zrotation", "Yrotation"),
            ("Zrotation", "Yrotation", "Xrotation"),
            (),
        ),
    )
    rng = np.random.default_rng(3)
    ch = rng.uniform(-120, 120, size=(15, skel.n_channels))
    rots, pos = global_transforms(skel, ch, position_mode="add")  # naive_fk adds offset + channels
    ref_rots, ref_pos = naive_fk(skel, ch)
    assert np.allclose(pos, ref_pos) and np.allclose(rots, ref_rots)
    assert np.allclose(local_rotations(skel, ch)[:, 3], np.eye(3))  # no rotation channels -> identity


def test_beat_skeleton_many_frames_against_naive_reference():
    # more frames than one internal block, so block boundaries are covered
    skel = beat_skeleton()
    rng = np.random.default_rng(11)
    n = kin._BLOCK + 37
    ch = rng.uniform(-60, 60, size=(n, skel.n_channels))
    ch[:, :3] = rng.normal(scale=20, size=(n, 3))
    rots, pos = global_transforms(skel, ch)
    sub = np.r_[0:3, kin._BLOCK - 1 : kin._BLOCK + 2, n - 1]
    ref_rots, ref_pos = naive_fk(skel, ch[sub])
    assert np.allclose(pos[sub], ref_pos, atol=1e-9) and np.allclose(rots[sub], ref_rots, atol=1e-12)
    assert np.allclose(forward_kinematics(skel, ch), pos)
    # End Sites: owner position + owner rotation @ End Site offset
    full = forward_kinematics(skel, ch, end_sites=True)
    owners = sorted(skel.end_sites)
    offs = np.stack([skel.end_sites[j] for j in owners])
    assert full.shape == (n, 75 + 13, 3)
    assert np.allclose(full[:, 75:], pos[:, owners] + np.einsum("tjkl,jl->tjk", rots[:, owners], offs))


def test_rotations_are_orthonormal_and_bone_lengths_preserved():
    skel = beat_skeleton()
    ch = np.random.default_rng(5).uniform(-400, 400, size=(50, skel.n_channels))
    rots, pos = global_transforms(skel, ch)
    assert np.allclose(rots @ np.swapaxes(rots, -1, -2), np.eye(3), atol=1e-12)
    child = np.arange(1, skel.n_joints)
    lengths = np.linalg.norm(pos[:, child] - pos[:, skel.parents[child]], axis=-1)
    assert np.allclose(lengths, skel.bone_lengths()[child])


def test_position_mode_add_versus_replace():
    skel = arm((POS + XYZ_ROT, POS + XYZ_ROT, XYZ_ROT))
    ch = np.zeros((1, skel.n_channels))
    ch[0, 6:9] = [0.0, 3.0, 0.0]  # elbow translation channels
    add = forward_kinematics(skel, ch, position_mode="add")[0]
    rep = forward_kinematics(skel, ch)[0]  # "replace" is the default (Blender's reading)
    assert np.allclose(add[1], [10, 3, 0])  # offset (10,0,0) + (0,3,0)
    assert np.allclose(rep[1], [0, 3, 0])  # (0,3,0) alone
    with pytest.raises(ValueError, match="position_mode"):
        forward_kinematics(skel, ch, position_mode="sum")


def test_input_validation():
    skel = arm()
    with pytest.raises(ValueError, match=r"\(T, 12\).*\(3, 11\)"):
        forward_kinematics(skel, np.zeros((3, 11)))
    with pytest.raises(ValueError, match=r"\(T, 12\).*\(12,\)"):
        forward_kinematics(skel, np.zeros(12))
    with pytest.raises(TypeError, match="Skeleton"):
        forward_kinematics("skeleton", np.zeros((1, 12)))
    with pytest.raises(TypeError, match="Skeleton"):
        rest_pose(None)
    bad = arm((POS + XYZ_ROT, ("Xrotation", "Xrotation", "Zrotation"), XYZ_ROT))
    with pytest.raises(ValueError, match="Elbow"):
        forward_kinematics(bad, np.zeros((1, 12)))
    assert forward_kinematics(skel, np.zeros((0, 12))).shape == (0, 3, 3)


# ------------------------------------------------------------------- real files
def test_real_beat_frame_is_a_plausible_standing_pose(real_samples):
    motion = read_bvh(real_samples / "beat_skeleton_2_scott_0_1_1_frame0.bvh")
    skel = motion.skeleton
    pos = forward_kinematics(skel, motion.channels, end_sites=True)[0]
    at = {n: pos[i] for i, n in enumerate(skel.names)}
    assert 40 < at["Head"][1] - at["Hips"][1] < 90
    assert at["RightHand"][1] < at["RightArm"][1] and at["LeftHand"][1] < at["LeftArm"][1]
    assert 20 < abs(at["RightHand"][0] - at["LeftHand"][0]) < 120
    lowest = pos[:, 1].min()
    feet = [at[n][1] for n in ("RightFoot", "LeftFoot", "RightToeBase", "LeftToeBase")]
    assert min(feet) - lowest < 5  # a foot joint is (nearly) the lowest point
    assert max(feet) - lowest < 25  # both feet near the floor
    # the same pose on beatlite's own skeleton (same topology, other offsets) is also upright
    own = forward_kinematics(beat_skeleton(), motion.channels)[0]
    assert 40 < own[skel.index("Head"), 1] - own[0, 1] < 90


def test_real_bandai_file_with_6_channels_per_joint(real_samples):
    motion = read_bvh(real_samples / "dataset-1_bye_normal_001.bvh")
    skel = motion.skeleton
    assert skel.rotation_order(3) == "ZXY" and all(len(c) == 6 for c in skel.channels)
    head, hips = skel.index("Head"), skel.index("Hips")
    for mode in ("add", "replace"):
        pos = forward_kinematics(skel, motion.channels, position_mode=mode)
        assert pos.shape == (motion.n_frames, skel.n_joints, 3) and np.all(np.isfinite(pos))
        assert np.all(pos[:, head, 1] > pos[:, hips, 1])
    # this file's position channels repeat the offsets; with "replace" each bone's length is the
    # length of its position channels (rotations preserve lengths)
    pos = forward_kinematics(skel, motion.channels, position_mode="replace")
    child = np.arange(1, skel.n_joints)
    lengths = np.linalg.norm(pos[:, child] - pos[:, skel.parents[child]], axis=-1)
    chan = np.stack(
        [np.linalg.norm(motion.channels[:, skel.position_channel_indices(j)], axis=1) for j in child], 1
    )
    assert np.allclose(lengths, chan)
