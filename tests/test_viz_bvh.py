"""BVH export of generated motion: subset -> full BEAT Motion -> .bvh -> beatlite.io -> same positions."""

from __future__ import annotations

import numpy as np
import pytest

from beatlite.io import read_bvh
from beatlite.skeleton.beat import JOINT_SUBSETS, beat_skeleton, subset_columns
from beatlite.skeleton.kinematics import forward_kinematics, rest_pose
from beatlite.viz.bvh_export import export_bvh, motion_from_subset


def generated_141(n_frames: int = 12, seed: int = 0) -> np.ndarray:
    """A stand-in for model output: smooth random Euler degrees in [-40, 40], (T, 141)."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 1, n_frames)[:, None]
    return 40 * np.sin(2 * np.pi * (rng.random(141) + t * rng.random(141)))


def test_motion_from_subset_places_channels_and_leaves_the_rest_at_zero():
    skel = beat_skeleton()
    values = generated_141()
    motion = motion_from_subset(values, 15, skel)
    assert motion.channels.shape == (12, 228) and motion.fps == 15.0
    cols = subset_columns(skel, "spine_neck_141")
    assert np.array_equal(motion.channels[:, cols], values)
    others = np.setdiff1d(np.arange(228), cols)
    assert others.size == 228 - 141 and not motion.channels[:, others].any()


def test_untouched_joints_stay_at_rest():
    skel = beat_skeleton()
    pos = motion_from_subset(generated_141(), 15, skel).positions()
    rest = rest_pose(skel)
    legs = [skel.index(n) for n in skel.names if any(w in n for w in ("UpLeg", "Foot", "Toe"))]
    assert len(legs) == 10
    # Hips has zero rotation and translation, so the legs (children of Hips only) are at rest
    assert np.allclose(pos[:, legs], rest[legs], atol=1e-9)
    # Spine1..3 are not in the subset, but the subset's Spine rotates them: they move
    spine3 = skel.index("Spine3")
    assert not np.allclose(pos[:, spine3], rest[spine3])


def test_root_position_is_applied():
    motion = motion_from_subset(generated_141(3), 15, root_position=(1.0, 95.0, -2.0))
    assert np.allclose(motion.positions()[:, 0], [1.0, 95.0, -2.0])


def test_bvh_round_trip_gives_the_same_positions(tmp_path):
    skel = beat_skeleton()
    values = generated_141(20, seed=3)
    path = export_bvh(tmp_path / "generated.bvh", values, fps=15, skeleton=skel)
    back = read_bvh(path)
    assert back.fps == pytest.approx(15.0)
    assert back.skeleton.names == skel.names
    assert np.allclose(back.channels[:, subset_columns(back.skeleton, "spine_neck_141")], values, atol=1e-6)
    expected = forward_kinematics(skel, motion_from_subset(values, 15, skel).channels)
    assert np.allclose(back.positions(), expected, atol=1e-4)  # 6 decimals of degrees -> < 1e-4 cm


def test_full_rows_and_other_subsets_are_accepted(tmp_path):
    skel = beat_skeleton()
    rows = np.zeros((4, 228))
    rows[:, 7] = 30.0
    assert np.array_equal(motion_from_subset(rows, 15, skel).channels, rows)
    body = np.full((4, 27), 10.0)
    motion = motion_from_subset(body, 15, skel, subset="body27")
    assert np.array_equal(motion.channels[:, subset_columns(skel, "body27")], body)
    assert len(JOINT_SUBSETS["body27"]) * 3 == 27


def test_bad_inputs_name_the_argument_and_shape():
    with pytest.raises(ValueError, match=r"\(T, 141\).*\(5, 140\)"):
        motion_from_subset(np.zeros((5, 140)), 15)
    with pytest.raises(ValueError, match="channels must be a"):
        motion_from_subset(np.zeros(141), 15)
    with pytest.raises(ValueError, match="NaN"):
        motion_from_subset(np.full((2, 141), np.nan), 15)
    with pytest.raises(ValueError, match="fps"):
        motion_from_subset(np.zeros((2, 141)), 0)
    with pytest.raises(ValueError, match="root_position"):
        motion_from_subset(np.zeros((2, 141)), 15, root_position=(0, 1))
