"""Tests of the BEAT skeleton table, its named subsets and the CaMN 141-d assembly."""

from __future__ import annotations

import numpy as np
import pytest

from beatlite.io import read_bvh
from beatlite.skeleton import (
    HIPS_HEIGHT_CM,
    JOINT_SUBSETS,
    beat_skeleton,
    camn_assemble,
    camn_split,
    expand_subset,
    rest_pose,
    subset_columns,
)

REAL_SKELETON = "beat_skeleton_2_scott_0_1_1_frame0.bvh"


@pytest.fixture(scope="module")
def real(real_samples):
    return read_bvh(real_samples / REAL_SKELETON).skeleton


def _height_and_span(skel) -> tuple[float, float]:
    """(top of HeadEnd End Site - lowest point, distance between the middle-finger tips) in rest pose."""
    pos = rest_pose(skel, end_sites=True)
    owners = sorted(skel.end_sites)
    tip = {skel.names[j]: pos[skel.n_joints + k] for k, j in enumerate(owners)}
    height = tip["HeadEnd"][1] - pos[:, 1].min()
    span = np.linalg.norm(tip["RightHandMiddle4"] - tip["LeftHandMiddle4"])
    return float(height), float(span)


# ------------------------------------------------------------------- topology vs the real file
def test_topology_equals_real_beat_header(real):
    skel = beat_skeleton()
    assert skel.n_joints == real.n_joints == 75
    assert skel.n_channels == real.n_channels == 228
    assert skel.names == real.names
    assert np.array_equal(skel.parents, real.parents)
    assert skel.channels == real.channels
    assert sorted(skel.end_sites) == sorted(real.end_sites)
    assert skel.same_topology(real)


def test_channel_layout_as_described():
    skel = beat_skeleton()
    assert skel.channels[0] == ("Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation")
    assert all(c == ("Xrotation", "Yrotation", "Zrotation") for c in skel.channels[1:])
    tips = {skel.names[j] for j in skel.end_sites}
    fingers = {
        f"{s}Hand{f}4" for s in ("Right", "Left") for f in ("Middle", "Ring", "Pinky", "Index", "Thumb")
    }
    assert tips == {"HeadEnd", "RightToeBaseEnd", "LeftToeBaseEnd"} | fingers
    # docs/reference_code.md#bvh-channels: the channel dict's end index for joint k is 6 + 3k
    starts = skel.channel_starts
    assert [int(starts[k]) + len(skel.channels[k]) for k in (1, 8, 74)] == [9, 30, 228]


def test_bone_lengths_within_35_percent_of_real(real):
    mine, theirs = beat_skeleton().bone_lengths(), real.bone_lengths()
    big = theirs > 2.0
    assert big.sum() > 40
    ratio = mine[big] / theirs[big]
    bad = [(n, round(float(r), 2)) for n, r, b in zip(real.names, mine / np.maximum(theirs, 1e-9), big) if b]
    assert np.all((ratio > 0.65) & (ratio < 1.35)), [x for x in bad if not 0.65 < x[1] < 1.35]


def test_height_and_arm_span_within_10_percent_of_real(real):
    h_mine, s_mine = _height_and_span(beat_skeleton())
    h_real, s_real = _height_and_span(real)
    assert abs(h_mine / h_real - 1) < 0.10
    assert abs(s_mine / s_real - 1) < 0.10


def test_anthropometry_and_rest_pose_conventions():
    skel = beat_skeleton()
    pos = rest_pose(skel, end_sites=True)
    name = {n: i for i, n in enumerate(skel.names)}
    height, span = _height_and_span(skel)
    assert 165 < height < 185  # ~175 cm adult
    floor = pos[:, 1].min()
    assert 95 <= pos[name["Hips"], 1] - floor <= 100
    assert np.isclose(pos[name["Hips"], 1] - floor, HIPS_HEIGHT_CM)
    assert 0.95 < span / height < 1.1
    # right side at -X, left mirrored
    for joint in ("RightArm", "RightHand", "RightUpLeg", "RightHandThumb4"):
        left = name[joint.replace("Right", "Left")]
        assert pos[name[joint], 0] < 0
        assert np.allclose(pos[left], pos[name[joint]] * [-1, 1, 1])
    # arms horizontal along -X: shoulder joint, elbow and wrist at one height and depth
    arm = pos[[name["RightArm"], name["RightForeArm"], name["RightHand"]]]
    assert np.allclose(arm[:, 1:], arm[0, 1:])
    assert np.all(np.diff(arm[:, 0]) < 0)
    # facing +Z: toes in front of the ankles, thumb tip in front of the index tip
    assert pos[name["RightToeBase"], 2] > pos[name["RightFoot"], 2] + 5
    assert pos[name["RightHandThumb4"], 2] > pos[name["RightHandIndex4"], 2] + 2
    # head above the shoulders, feet at the bottom
    assert pos[name["HeadEnd"], 1] > pos[name["RightArm"], 1] > pos[name["Hips"], 1]
    assert floor == pytest.approx(min(pos[name["RightToeBase"], 1], pos[name["RightToeBaseEnd"], 1]))


def test_each_finger_has_three_or_four_phalanges_with_spread():
    skel = beat_skeleton()
    pos = rest_pose(skel)
    name = {n: i for i, n in enumerate(skel.names)}
    for finger in ("Middle", "Ring", "Pinky", "Index", "Thumb"):
        chain = [n for n in skel.names if n.startswith(f"RightHand{finger}") and n[-1].isdigit()]
        assert 3 <= len(chain) - 1 <= 4
        assert all(1.0 < skel.bone_lengths()[name[n]] < 10.0 for n in chain[1:])
    # fingertips spread along Z: index > middle > ring > pinky
    z = [pos[name[f"RightHand{f}4"], 2] for f in ("Index", "Middle", "Ring", "Pinky")]
    assert z == sorted(z, reverse=True)


def test_new_object_each_call():
    a, b = beat_skeleton(), beat_skeleton()
    assert a is not b and a.offsets is not b.offsets


# ------------------------------------------------------------------- subsets
def test_subset_sizes_and_body27_names():
    assert {k: len(v) for k, v in JOINT_SUBSETS.items()} == {
        "body27": 9,
        "hands114": 38,
        "spine_neck_141": 47,
        "upper_body": 75 - 12,  # 6 leg joints per side
        "fingers": 2 * (4 + 5 + 5 + 5 + 4),  # Middle1-4, Ring+1-4, Pinky+1-4, Index+1-4, Thumb1-4
    }
    assert JOINT_SUBSETS["body27"] == (
        "Spine",
        "Neck",
        "Neck1",
        "RightShoulder",
        "RightArm",
        "RightForeArm",
        "LeftShoulder",
        "LeftArm",
        "LeftForeArm",
    )
    names = set(beat_skeleton().names)
    for subset in JOINT_SUBSETS.values():
        assert set(subset) <= names and len(set(subset)) == len(subset)
    assert "Hips" in JOINT_SUBSETS["upper_body"]
    assert not any("Leg" in n or "Foot" in n or "Toe" in n for n in JOINT_SUBSETS["upper_body"])
    assert not any(n.endswith("Hand") for n in JOINT_SUBSETS["fingers"])


def test_spine_neck_141_is_depth_first_order_minus_excluded_joints():
    # docs/reference_code.md#joint-subsets: excluded are Hips, Spine1-3, Head, HeadEnd, the ten *4 tips and the 12 legs.
    skel = beat_skeleton()
    excluded = {"Hips", "Spine1", "Spine2", "Spine3", "Head", "HeadEnd"}
    keep = [
        n
        for n in skel.names
        if n not in excluded and not n.endswith("4") and not any(w in n for w in ("Leg", "Foot", "Toe"))
    ]
    assert tuple(keep) == JOINT_SUBSETS["spine_neck_141"]
    # index map of docs/reference_code.md#joint-subsets: joints 3-5 right shoulder/arm/forearm, 25-27 the left ones
    s = JOINT_SUBSETS["spine_neck_141"]
    assert s[3:6] == ("RightShoulder", "RightArm", "RightForeArm")
    assert s[25:28] == ("LeftShoulder", "LeftArm", "LeftForeArm")
    assert s[6] == "RightHand" and s[28] == "LeftHand"


def test_subset_columns_on_real_and_own_skeleton(real):
    cols = subset_columns(beat_skeleton(), "spine_neck_141")
    assert cols.dtype == np.int64 and cols.shape == (141,)
    # Spine is joint 1: after the 6 Hips channels -> columns 6, 7, 8; Neck is joint 5 -> 18, 19, 20
    assert cols[:6].tolist() == [6, 7, 8, 18, 19, 20]
    assert np.array_equal(cols, subset_columns(real, "spine_neck_141"))
    assert len(set(cols.tolist())) == 141
    with pytest.raises(ValueError, match="subset_name"):
        subset_columns(beat_skeleton(), "body28")
    with pytest.raises(TypeError, match="Skeleton"):
        subset_columns("beat", "body27")


def test_camn_assemble_by_names_equals_spine_neck_141_order():
    body = np.array(JOINT_SUBSETS["body27"], dtype=object).repeat(3)
    hands = np.array(JOINT_SUBSETS["hands114"], dtype=object).repeat(3)
    assembled = camn_assemble(body, hands)
    assert tuple(assembled[::3]) == JOINT_SUBSETS["spine_neck_141"]
    # the same with channel columns: assembly of the parts' columns gives the 141 columns
    skel = beat_skeleton()
    cols = camn_assemble(subset_columns(skel, "body27"), subset_columns(skel, "hands114"))
    assert np.array_equal(cols, subset_columns(skel, "spine_neck_141"))


def test_camn_assemble_matches_reference_slices_and_split_inverts():
    rng = np.random.default_rng(0)
    body, hands = rng.normal(size=(2, 5, 27)), rng.normal(size=(2, 5, 114))
    out = camn_assemble(body, hands)
    assert out.shape == (2, 5, 141)
    assert np.array_equal(out[..., 0:18], body[..., 0:18])
    assert np.array_equal(out[..., 18:75], hands[..., 0:57])
    assert np.array_equal(out[..., 75:84], body[..., 18:27])
    assert np.array_equal(out[..., 84:141], hands[..., 57:114])
    b2, h2 = camn_split(out)
    assert np.array_equal(b2, body) and np.array_equal(h2, hands)
    with pytest.raises(ValueError, match=r"body27.*\(5, 26\)"):
        camn_assemble(np.zeros((5, 26)), np.zeros((5, 114)))
    with pytest.raises(ValueError, match="leading"):
        camn_assemble(np.zeros((5, 27)), np.zeros((4, 114)))
    with pytest.raises(ValueError, match="141"):
        camn_split(np.zeros((3, 140)))


def test_expand_subset_places_values_and_fills():
    skel = beat_skeleton()
    cols = subset_columns(skel, "spine_neck_141")
    vals = np.arange(2 * 141, dtype=float).reshape(2, 141)
    full = expand_subset(vals, "spine_neck_141")
    assert full.shape == (2, 228)
    assert np.array_equal(full[:, cols], vals)
    others = np.setdiff1d(np.arange(228), cols)
    assert others.size == 228 - 141 and np.all(full[:, others] == 0)
    fill = np.full(228, 7.0)
    full2 = expand_subset(vals, "spine_neck_141", skel, fill=fill)
    assert np.all(full2[:, others] == 7.0) and np.array_equal(full2[:, cols], vals)
    assert np.all(fill == 7.0)  # not modified
    one = expand_subset(np.ones(27), "body27")
    assert one.shape == (1, 228) and one.sum() == 27
    with pytest.raises(ValueError, match=r"\(T, 141\).*\(2, 140\)"):
        expand_subset(np.zeros((2, 140)), "spine_neck_141")
    with pytest.raises(ValueError, match="fill"):
        expand_subset(vals, "spine_neck_141", fill=np.zeros((3, 228)))
