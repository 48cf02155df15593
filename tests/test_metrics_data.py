"""Metric sanity on the embedded corpus ``data_samples/`` (test-split takes; slow).

Ground truth against itself scores the best possible value; ground truth against a
time-shuffled copy (1-second blocks in random order, so the motion stays locally smooth but
loses its timing) scores clearly worse on BeatAlign, BC and SRGR; a frozen mean pose scores
worst on diversity.
"""

from __future__ import annotations

import numpy as np
import pytest

from beatlite.metrics import beat_align, beat_consistency, diversity, fgd, l1_diversity, srgr
from beatlite.metrics.beats import mean_angle_change

pytestmark = pytest.mark.slow

BLOCK = 15  # frames = 1 s at 15 fps
ARM_JOINTS = ("RightArm", "RightForeArm", "RightHand", "LeftArm", "LeftForeArm", "LeftHand")


@pytest.fixture(scope="module")
def takes(data_samples):
    from beatlite.data.index import index_folder
    from beatlite.io import load_take

    records = list(index_folder(data_samples).where(split="test", usable=True))
    if not records:
        pytest.fail("data_samples/ has no usable test-split take")
    return [load_take(r.path("motion")) for r in records]


def block_shuffle(x: np.ndarray, seed: int = 0) -> np.ndarray:
    """Frames of ``x`` regrouped as 1-second blocks in a random order (a derangement of the blocks)."""
    n = len(x) // BLOCK
    rng = np.random.default_rng(seed)
    order = np.arange(n)
    while n > 1 and np.any(order == np.arange(n)):
        order = rng.permutation(n)
    blocks = [x[i * BLOCK : (i + 1) * BLOCK] for i in order] + [x[n * BLOCK :]]
    return np.concatenate(blocks)


def ted_directions(take):
    from beatlite.skeleton.directions import positions_to_directions
    from beatlite.skeleton.ted import TED_BONES, beat_to_ted43

    return positions_to_directions(beat_to_ted43(take.motion), np.asarray(TED_BONES))


def test_srgr_ground_truth_is_best_and_shuffle_is_worse(takes):
    pos = [t.positions() for t in takes]
    sem = [np.asarray(t.semantic, dtype=np.float64) for t in takes]
    frames = np.array([len(p) for p in pos])
    best = float((np.array([s.mean() for s in sem]) * frames).sum() / frames.sum())
    assert srgr(pos, pos, sem) == pytest.approx(best)
    if best == 0:
        pytest.skip("test takes carry no semantic score")
    shuffled = srgr([block_shuffle(p) for p in pos], pos, sem)
    assert shuffled < 0.7 * best


def test_beat_align_ground_truth_beats_shuffled(takes):
    sk = takes[0].motion.skeleton
    joints = sk.indices(list(ARM_JOINTS))
    audio = [t.audio for t in takes]
    pos = [t.positions() for t in takes]
    pos = [p[:, joints] for p in pos]
    gt = beat_align(audio, takes[0].sr, pos, takes[0].fps)
    shuffled = np.mean(
        [beat_align(audio, takes[0].sr, [block_shuffle(p, s) for p in pos], takes[0].fps) for s in range(3)]
    )
    assert 0 < gt <= 1
    assert shuffled < gt - 0.03


def test_beat_consistency_ground_truth_beats_shuffled(takes):
    audio = [t.audio for t in takes]
    dirs = [ted_directions(t) for t in takes]
    from beatlite.metrics.consistency import default_angle_pairs, prepare_directions

    maac = mean_angle_change([prepare_directions(d) for d in dirs], default_angle_pairs())
    gt = beat_consistency(audio, takes[0].sr, dirs, takes[0].fps, change_angle=maac)
    shuffled = np.mean(
        [
            beat_consistency(
                audio, takes[0].sr, [block_shuffle(d, s) for d in dirs], takes[0].fps, change_angle=maac
            )
            for s in range(3)
        ]
    )
    assert 0 < gt <= 1
    assert shuffled < gt - 0.03


def test_beat_consistency_ground_truth_is_stable_under_round_off(takes):
    # Two of HA2G's pairs (nose->eye vs eye->ear) are rigid on BEAT's skeleton (MAAC ~ 1e-16);
    # without drop_rigid_pairs, 1e-9 noise moved the evaluation's GT BC from 0.7325 to 0.7383.
    from beatlite.metrics.consistency import default_angle_pairs, prepare_directions

    audio = [t.audio for t in takes]
    dirs = [ted_directions(t) for t in takes]
    maac = mean_angle_change([prepare_directions(d) for d in dirs], default_angle_pairs())
    gt = beat_consistency(audio, takes[0].sr, dirs, takes[0].fps, change_angle=maac)
    rng = np.random.default_rng(0)
    noisy = [d + 1e-9 * rng.standard_normal(d.shape) for d in dirs]
    assert abs(beat_consistency(audio, takes[0].sr, noisy, takes[0].fps, change_angle=maac) - gt) < 0.005


def test_fgd_zero_and_frozen_pose_has_the_least_diversity(takes):
    from beatlite.data.windows import sliding_windows

    dirs = [ted_directions(t).reshape(-1, 126) for t in takes]
    windows = np.concatenate([sliding_windows(d, 34, 10) for d in dirs])
    mean_pose = np.concatenate(dirs).mean(axis=0)
    frozen = [np.repeat(mean_pose[None], len(d), axis=0) for d in dirs]
    frozen_windows = np.concatenate([sliding_windows(d, 34, 10) for d in frozen])
    try:
        from beatlite.metrics.extractor import load_extractor

        extractor = load_extractor("dirvec")
    except FileNotFoundError:
        extractor = None
    if extractor is not None:
        # the extractor's space is the train-mean-subtracted directions; subtracting any constant
        # leaves FGD(X, X) = 0 and the frozen windows still all equal
        real = windows - mean_pose
        feats, frozen_feats = extractor(real), extractor(frozen_windows - mean_pose)
    else:
        feats, frozen_feats = windows.mean(axis=1), frozen_windows.mean(axis=1)
    assert fgd(feats, feats) == pytest.approx(0.0, abs=1e-6)
    assert diversity(frozen_feats) == pytest.approx(0.0, abs=1e-9)
    assert diversity(feats) > 0
    assert l1_diversity(frozen) == pytest.approx(0.0, abs=1e-9)
    assert l1_diversity(dirs) > 0


@pytest.fixture(scope="module")
def split_windows(data_samples):
    from beatlite.data.index import index_folder
    from beatlite.data.windows import build_windows

    index = index_folder(data_samples)
    train = build_windows(index, split="train")
    stats = train.normalizers
    return (
        train,
        build_windows(index, split="val", stats=stats),
        build_windows(index, split="test", stats=stats),
    )


@pytest.mark.parametrize("space", ["dirvec", "pose", "rot6d"])
def test_shipped_extractor_matches_the_corpus_and_ranks_broken_motion_worse(space, split_windows):
    from beatlite.metrics.extractor import SPACES, load_extractor, space_input

    train, val, test = split_windows
    key = SPACES[space][0]
    loaded = load_extractor(space)

    def ex(windows):  # rot6d: the raw Euler windows as 6D rotations first
        return loaded(np.asarray(space_input(windows, space), np.float32))

    ex.meta = loaded.meta
    # files (content) + parameters: the same on every machine (float bytes are not: other CPUs, builds)
    assert ex.meta["data_fingerprint"] == train.fingerprint, (
        f"checkpoint is stale: retrain with `python -m beatlite.metrics.extractor train --space {space}`"
    )
    real, held_out = ex(np.asarray(test[key])), ex(np.asarray(val[key]))
    rng = np.random.default_rng(0)
    shuffled = ex(np.asarray(test[key])[:, rng.permutation(34)])  # same poses, frames out of order
    frozen_window = np.broadcast_to(
        np.asarray(test[key]).mean(axis=(0, 1), keepdims=True), np.shape(test[key])
    )
    frozen = ex(frozen_window) + 1e-6 * rng.normal(size=real.shape)  # one point: jitter for a covariance
    base = fgd(real, held_out)
    assert fgd(shuffled, real) > 1.5 * base
    assert fgd(frozen, real) > 3 * base
