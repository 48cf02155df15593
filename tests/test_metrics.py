"""Tests of beatlite.metrics: FGD, SRGR, diversity, extras, evaluate (numpy only, fast)."""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest
from childproc import run_ok
from scipy import linalg

from beatlite.data.windows import sliding_windows
from beatlite.metrics import (
    GroundTruth,
    Takes,
    beat_align,
    beat_consistency,
    diversity,
    evaluate,
    fgd,
    fit_gaussian,
    frechet_distance,
    jerk_stats,
    l1_diversity,
    mae,
    mpjpe,
    pck,
    srgr,
    velocity_stats,
)
from beatlite.metrics.recall import srgr_per_frame


def test_import_does_not_import_torch():
    code = "import sys, beatlite.metrics; assert 'torch' not in sys.modules, 'torch imported'"
    run_ok([sys.executable, "-c", code])


# ----------------------------------------------------------------------------- FGD
def test_fgd_of_a_set_with_itself_is_zero():
    x = np.random.default_rng(0).normal(size=(300, 20))
    assert fgd(x, x) == pytest.approx(0.0, abs=1e-9)


def test_fgd_symmetric_and_nonnegative():
    rng = np.random.default_rng(1)
    for _ in range(5):
        x = rng.normal(size=(100, 8)) @ rng.normal(size=(8, 8))
        y = rng.normal(size=(150, 8)) * rng.uniform(0.1, 3, 8) + rng.normal(size=8)
        assert fgd(x, y) >= 0
        assert fgd(x, y) == pytest.approx(fgd(y, x), rel=1e-9)


def test_frechet_closed_form_diagonal():
    # Commuting diagonal covariances: d = |mu1 - mu2|^2 + sum_i (s1_i - s2_i)^2 (s = standard deviations).
    mu1, mu2 = np.array([0.0, 1.0, 2.0]), np.array([1.0, 1.0, 0.0])
    s1, s2 = np.array([1.0, 2.0, 3.0]), np.array([2.0, 2.0, 1.0])
    expected = (1 + 0 + 4) + (1 + 0 + 4)  # 10
    d = frechet_distance(mu1, np.diag(s1**2), mu2, np.diag(s2**2))
    assert d == pytest.approx(expected, rel=1e-12)


def test_frechet_two_d_written_out():
    # sigma1 = I, sigma2 = [[2,1],[1,2]] (eigenvalues 3 and 1), mu2 - mu1 = (1, 2):
    # d = 5 + tr(I) + tr(sigma2) - 2 tr(sigma2^1/2) = 5 + 2 + 4 - 2 (sqrt 3 + 1) = 9 - 2 sqrt 3.
    s2 = np.array([[2.0, 1.0], [1.0, 2.0]])
    d = frechet_distance(np.zeros(2), np.eye(2), np.array([1.0, 2.0]), s2)
    assert d == pytest.approx(9 - 2 * math.sqrt(3), rel=1e-12)


def test_frechet_non_commuting_two_d():
    # sigma1 = diag(4, 1), sigma2 = [[2,1],[1,2]]: M = sigma1^1/2 sigma2 sigma1^1/2 = [[8,2],[2,2]];
    # for a 2x2 PSD M, tr sqrt(M) = sqrt(tr M + 2 sqrt(det M)) = sqrt(10 + 2 sqrt 12).
    # d = 0 + 5 + 4 - 2 sqrt(10 + 2 sqrt 12)
    s1, s2 = np.diag([4.0, 1.0]), np.array([[2.0, 1.0], [1.0, 2.0]])
    expected = 9 - 2 * math.sqrt(10 + 2 * math.sqrt(12))
    assert frechet_distance(np.zeros(2), s1, np.zeros(2), s2) == pytest.approx(expected, rel=1e-12)
    assert frechet_distance(np.zeros(2), s1, np.zeros(2), s2, reference=True) == pytest.approx(
        expected, rel=1e-9
    )


def test_stable_matches_scipy_sqrtm_oracle():
    rng = np.random.default_rng(2)
    a, b = rng.normal(size=(400, 30)), rng.normal(size=(500, 30)) @ rng.normal(size=(30, 30)) * 0.3
    mu1, s1 = a.mean(0), np.cov(a, rowvar=False)
    mu2, s2 = b.mean(0), np.cov(b, rowvar=False)
    oracle = ((mu1 - mu2) ** 2).sum() + np.trace(s1 + s2) - 2 * np.trace(linalg.sqrtm(s1 @ s2).real)
    assert frechet_distance(mu1, s1, mu2, s2) == pytest.approx(oracle, rel=1e-7)
    assert fgd(a, b, reference=True) == pytest.approx(oracle, rel=1e-7)


def test_frechet_rank_deficient_covariance_is_finite():
    # 5 samples in 20 dims: singular covariances; tiny negative eigenvalues must be clipped.
    rng = np.random.default_rng(3)
    x, y = rng.normal(size=(5, 20)), rng.normal(size=(6, 20))
    d = fgd(x, y)
    assert np.isfinite(d) and d >= 0


def test_fit_gaussian_equals_numpy_cov():
    x = np.random.default_rng(4).normal(size=(50, 4))
    mu, s = fit_gaussian(x)
    np.testing.assert_allclose(mu, x.mean(0))
    np.testing.assert_allclose(s, np.cov(x, rowvar=False))


def test_fgd_errors_name_the_argument():
    with pytest.raises(ValueError, match="generated needs at least 2 samples"):
        fgd(np.zeros((1, 3)), np.zeros((5, 3)))
    with pytest.raises(ValueError, match="real needs at least 2"):
        fgd(np.zeros((4, 3)), np.zeros((1, 3)))
    with pytest.raises(ValueError, match="real must be 2-D"):
        fgd(np.zeros((4, 3)), np.zeros(5))
    with pytest.raises(ValueError, match="width"):
        fgd(np.ones((4, 3)), np.ones((4, 2)))
    with pytest.raises(ValueError, match="sigma2"):
        frechet_distance(np.zeros(2), np.eye(2), np.zeros(2), np.eye(3))


def test_fgd_with_a_pluggable_extractor():
    # Extractor = mean over time; windows with equal time-means have FGD 0.
    rng = np.random.default_rng(5)
    w = rng.normal(size=(40, 34, 3))
    flipped = w[:, ::-1]  # same per-window mean over time

    def extractor(x):
        return x.mean(axis=1)

    assert fgd(w, flipped, extractor=extractor) == pytest.approx(0.0, abs=1e-9)
    with pytest.raises(ValueError, match="extractor must map"):
        fgd(w, w, extractor=lambda x: x.mean(axis=(1, 2)))


# ----------------------------------------------------------------------------- SRGR
def _positions(t=6, j=4, seed=0):
    return np.random.default_rng(seed).normal(scale=20, size=(t, j, 3))


def test_srgr_paper_perfect_prediction_is_mean_semantic():
    p = _positions()
    sem = np.array([0.0, 0.1, 0.8, 0.5, 1.0, 0.2])
    assert srgr(p, p, sem) == pytest.approx(sem.mean())


def test_srgr_paper_all_miss_is_zero():
    p = _positions()
    assert srgr(p + np.array([0, 0, 10.5]), p, np.ones(6), delta=10.0) == 0.0  # every error 10.5 cm >= 10


def test_srgr_paper_hand_computed():
    # T = 2, J = 2, delta = 10 cm, semantic [0.5, 1.0]:
    # frame 0 errors [0, 20] -> hits [1, 0]; frame 1 errors [5, 12] -> hits [1, 0]
    # SRGR = (0.5 * 1 + 1.0 * 1) / (2 * 2) = 0.375
    gt = np.zeros((2, 2, 3))
    gen = gt.copy()
    gen[0, 1, 0] = 20.0
    gen[1, 0, 1] = 5.0
    gen[1, 1, 2] = 12.0
    assert srgr(gen, gt, np.array([0.5, 1.0]), delta=10.0) == pytest.approx(0.375)
    np.testing.assert_allclose(srgr_per_frame(gen, gt, np.array([0.5, 1.0]), delta=10.0), [0.25, 0.5])


def test_srgr_reference_hand_computed():
    # Euler degrees, T = 2, C = 6 (J = 2), threshold 4 on the summed |diff|, weight sem / 0.165:
    # frame 0: joint 0 |1|+|1|+|1| = 3 < 4 hit; joint 1 2+2+0 = 4 miss; weight 0.33/0.165 = 2 -> 2
    # frame 1: joint 0 0 hit; joint 1 1 hit;                   weight 0.165/0.165 = 1 -> 2
    # SRGR = (2 + 2) / (2 * 2) = 1.0
    gt = np.zeros((2, 6))
    gen = np.array([[1, -1, 1, 2, 2, 0], [0, 0, 0, 0, 0, 1.0]])
    assert srgr(gen, gt, np.array([0.33, 0.165]), variant="reference") == pytest.approx(1.0)


def test_srgr_takes_are_frame_weighted():
    # take A: T = 1, perfect, sem 1 -> 1.0; take B: T = 3, all miss -> 0. Pooled: (1*1 + 3*0) / 4 = 0.25
    a = np.zeros((1, 2, 3))
    b = np.zeros((3, 2, 3))
    value = srgr([a, b + 100.0], [a, b], [np.ones(1), np.ones(3)])
    assert value == pytest.approx(0.25)


def test_srgr_errors():
    p = _positions()
    with pytest.raises(ValueError, match="semantic must have one value per frame"):
        srgr(p, p, np.ones(5))
    with pytest.raises(ValueError, match="same shape"):
        srgr(p, p[:, :3], np.ones(6))
    with pytest.raises(ValueError, match="variant"):
        srgr(p, p, np.ones(6), variant="paperish")
    with pytest.raises(ValueError, match="generated must be 2-D"):
        srgr(p, p, np.ones(6), variant="reference")


# ----------------------------------------------------------------------------- diversity
def test_l1_diversity_hand_computed():
    # one take [0, 2, 4]: mean 2, sum |x - 2| = 4, / 3 frames
    assert l1_diversity(np.array([[0.0], [2.0], [4.0]])) == pytest.approx(4 / 3)
    # two takes: [0, 2] (mean 1, sum 2) and four frames of 1 (sum 0): 2 / 6 frames
    assert l1_diversity([np.array([[0.0], [2.0]]), np.ones((4, 1))]) == pytest.approx(2 / 6)


def test_l1_diversity_windowed_quirk_hand_computed():
    # x = 0..4, windows of 3 every 1: [0,1,2] [1,2,3] [2,3,4] -> 9 frames, mean 2,
    # sum |x - 2| = 2+1+0 + 1+0+1 + 0+1+2 = 8 -> 8 / 9; without windows: 6 / 5.
    x = np.arange(5.0)[:, None]
    assert l1_diversity(x, windowed=True, length=3, stride=1) == pytest.approx(8 / 9)
    assert l1_diversity(x) == pytest.approx(6 / 5)


def test_diversity_of_identical_clips_is_zero():
    assert l1_diversity(np.ones((10, 5))) == 0.0
    assert diversity(np.ones((10, 4))) == 0.0


def test_diversity_hand_computed_and_deterministic():
    # two clips [0, 0] and [1, 3]: every pair of distinct clips is at L1 distance 4
    f = np.array([[0.0, 0.0], [1.0, 3.0]])
    assert diversity(f, n_pairs=37, seed=5) == pytest.approx(4.0)
    g = np.random.default_rng(0).normal(size=(20, 6))
    assert diversity(g, seed=3) == diversity(g, seed=3)


def test_diversity_matches_the_mean_over_all_pairs():
    # uniform random pairs of distinct clips -> expectation = mean over all ordered distinct pairs
    g = np.random.default_rng(1).normal(size=(12, 5))
    d = np.abs(g[:, None] - g[None]).sum(-1)
    exact = d.sum() / (12 * 11)
    assert diversity(g, n_pairs=200_000, seed=0) == pytest.approx(exact, rel=0.01)


def test_diversity_batch_pairing_quirk():
    # one batch: the permutation can only pair it with itself -> all rows meet themselves -> 0
    b = np.random.default_rng(2).normal(size=(8, 3))
    assert diversity([b], batch_pairing=True) == 0.0
    # loop oracle with the same permutation
    batches = [np.random.default_rng(k).normal(size=(4, 3)) for k in range(6)]
    perm = np.random.default_rng(7).permutation(6)[:3]
    rows = [np.abs(batches[i][r] - batches[perm[i]][r]).sum() for i in range(3) for r in range(4)]
    assert diversity(batches, n_pairs=3, seed=7, batch_pairing=True) == pytest.approx(np.mean(rows))


def test_diversity_ha2g_variant_pairs_batches_of_windows_in_test_order():
    # 40 windows -> 2 batches of 16 (the last 8 dropped, as HA2G's drop_last loader); the permutation of 2 batches
    # is either the identity (every row meets itself: 0) or the swap (row r of batch 0 with row r of batch 1).
    from beatlite.metrics.scoring import DIVERSITY_BATCH

    assert DIVERSITY_BATCH == 16
    feats = np.zeros((40, 2))
    feats[16:32] = [3.0, 4.0]  # batch 1 is 7 (L1) away from batch 0, row by row
    takes = Takes(positions=[np.zeros((40, 2, 3))], features=feats)
    for seed in range(6):
        swap = np.random.default_rng(seed).permutation(2)[0] == 1
        value = evaluate(takes, GroundTruth(takes), metrics=("Diversity (ha2g)",), seed=seed).get(
            "Diversity (ha2g)"
        )
        assert value.value == (7.0 if swap else 0.0)
    one_batch = Takes(positions=[np.zeros((31, 2, 3))], features=np.zeros((31, 2)))
    skipped = evaluate(one_batch, GroundTruth(one_batch), metrics=("Diversity (ha2g)",)).skipped
    assert skipped == {"Diversity (ha2g)": "needs at least 2 batches of 16 windows, got 31 windows"}


def test_diversity_errors():
    with pytest.raises(ValueError, match="at least 2 clips"):
        diversity(np.ones((1, 3)))
    with pytest.raises(TypeError, match="list of batches"):
        diversity(np.ones((4, 3)), batch_pairing=True)


# ----------------------------------------------------------------------------- extras
def test_pck_mae_mpjpe_hand_computed():
    gt = np.zeros((1, 4, 3))
    gen = np.zeros((1, 4, 3))
    gen[0, :, 0] = [0.0, 3.0, 12.0, 4.0]  # errors 0, 3, 12, 4
    assert pck(gen, gt, delta=5.0) == pytest.approx(3 / 4)
    assert mpjpe(gen, gt) == pytest.approx(19 / 4)
    assert mae(gen, gt) == pytest.approx(19 / 12)


def test_velocity_and_jerk_closed_forms():
    fps = 15.0
    t = np.arange(10.0)
    lin = np.zeros((10, 1, 3))
    lin[:, 0, 0] = 2 * t  # 2 cm per frame -> 30 cm/s
    v = velocity_stats(lin, fps)
    assert v["mean"] == pytest.approx(30.0) and v["std"] == pytest.approx(0.0, abs=1e-9)
    cubic = np.zeros((10, 1, 3))
    cubic[:, 0, 1] = t**3  # third difference of t^3 is 6 -> 6 fps^3
    assert jerk_stats(cubic, fps)["mean"] == pytest.approx(6 * fps**3)


def test_sliding_windows():
    x = np.arange(10)
    w = sliding_windows(x, 4, 3)  # starts 0, 3, 6
    np.testing.assert_array_equal(w, [[0, 1, 2, 3], [3, 4, 5, 6], [6, 7, 8, 9]])
    assert sliding_windows(x, 11, 1).shape == (0, 11)


# ----------------------------------------------------------------------------- evaluate
def test_evaluate_ground_truth_against_itself():
    rng = np.random.default_rng(0)
    pos = np.cumsum(rng.normal(size=(60, 5, 3)), axis=0)
    sem = rng.uniform(0, 1, 60)
    feats = sliding_windows(pos.reshape(60, -1), 34, 2).mean(axis=1)  # a stand-in extractor
    takes = Takes(positions=[pos], features=feats)
    rep = evaluate(takes, GroundTruth(takes, semantic=[sem]))
    assert rep.get("FGD").value == pytest.approx(0.0, abs=1e-9)
    assert rep.get("SRGR").value == pytest.approx(sem.mean())
    assert rep.get("PCK").value == 1.0
    assert rep.get("MPJPE").value == 0.0
    assert rep.skipped["BeatAlign"] == "needs beats" and rep.skipped["BC"].startswith("needs directions")
    assert rep.skipped["Diversity (ha2g)"].startswith("needs at least 2 batches")  # 14 windows
    md = rep.to_markdown()
    assert md.splitlines()[0] == "| metric | variant | value | better | definition |"
    assert "| SRGR | paper |" in md and "skipped" in md
    with pytest.raises(KeyError, match="no metric"):
        rep.get("nonsense")
    with pytest.raises(ValueError, match="unknown metric"):
        evaluate(takes, GroundTruth(takes), metrics=("nonsense",))


def test_evaluate_rejects_mismatched_takes():
    p = np.zeros((10, 3, 3))
    with pytest.raises(ValueError, match="frames"):
        evaluate(Takes(positions=[p]), GroundTruth(Takes(positions=[p[:5]])))
    with pytest.raises(ValueError, match="takes"):
        evaluate(Takes(positions=[p, p]), GroundTruth(Takes(positions=[p])))


def test_evaluate_variants_equal_the_metric_functions_on_beat_skeleton_motion():
    from beatlite.metrics.beats import mean_angle_change
    from beatlite.metrics.consistency import default_angle_pairs, prepare_directions
    from beatlite.skeleton.beat import beat_skeleton, subset_columns
    from beatlite.skeleton.directions import positions_to_directions
    from beatlite.skeleton.kinematics import forward_kinematics
    from beatlite.skeleton.ted import TED_BONES, beat_to_ted43

    sk = beat_skeleton()
    rng = np.random.default_rng(0)
    t = np.arange(180) / 15.0
    channels = np.zeros((180, sk.n_channels))
    channels[:, 6:] = 15 * np.sin(2 * np.pi * 0.7 * t[:, None] + rng.uniform(0, 6, sk.n_channels - 6))
    pos = forward_kinematics(sk, channels)
    dirs = positions_to_directions(beat_to_ted43(pos), np.asarray(TED_BONES))
    euler = channels[:, subset_columns(sk, "spine_neck_141")]
    audio = np.zeros(12 * 16000, np.float32)
    audio[16000 * np.arange(1, 12)] = 0.9  # one-sample clicks every second
    maac = mean_angle_change([prepare_directions(dirs)], default_angle_pairs())
    takes = Takes(positions=[pos], directions=[dirs], euler=[euler])
    truth = GroundTruth(takes, semantic=[np.full(180, 0.5)], audio=[audio], change_angle=maac)
    rep = evaluate(takes, truth)
    assert rep.get("BeatAlign").value == beat_align(audio, 16000, pos, 15)
    assert rep.get("BeatAlign (reference)").value == beat_align(audio, 16000, euler, 15, variant="reference")
    assert rep.get("BC").value == beat_consistency(audio, 16000, dirs, 15, change_angle=maac)
    assert rep.get("BC (ha2g)").value == beat_consistency(
        audio, 16000, dirs, 15, change_angle=maac, variant="ha2g"
    )
    assert rep.get("SRGR (reference)").value == pytest.approx(0.5 / 0.165)
    assert rep.get("L1div (reference)").value == l1_diversity(euler, windowed=True)
    assert {"FGD", "Diversity"} <= set(rep.skipped)  # no features given


# ----------------------------------------------------------------------------- named variants of other papers
def _root_and_joint(x: np.ndarray) -> np.ndarray:
    """(T, 2, 3) positions: a fixed root at the origin and one joint at (x_t, 0, 0) cm."""
    pos = np.zeros((len(x), 2, 3))
    pos[:, 1, 0] = x
    return pos


def test_genea_acceleration_and_jerk_of_polynomial_paths():
    """x = a t^2 / 2 has |x''| = a at every frame, x = j t^3 / 6 has |x'''| = j; the fixed root is left out and
    takes count equally whatever their length (GENEA's mean over sequences)."""
    fps = 15.0
    t30, t50 = np.arange(30) / fps, np.arange(50) / fps
    quadratic = [_root_and_joint(2.0 * t30**2 / 2), _root_and_joint(6.0 * t50**2 / 2)]
    cubic = [_root_and_joint(6.0 * t30**3 / 6), _root_and_joint(12.0 * t50**3 / 6)]
    for takes, key, want in ((quadratic, "Acceleration (GENEA)", 4.0), (cubic, "Jerk (GENEA)", 9.0)):
        truth = GroundTruth(Takes(positions=takes), fps=fps)
        assert evaluate(Takes(positions=takes), truth, metrics=[key]).get(key).value == pytest.approx(
            want, rel=1e-6
        )


def test_genea_speed_hellinger_of_two_histograms():
    """Generated: the joint always moves at 2.5 cm/s (bin [2, 3)); truth: 20 frames at 2.5 and 20 at 5.5 cm/s
    (bins [2, 3) and [5, 6)). H = sqrt(1 - sqrt(1 * 1/2)); the fixed root (speed 0) is not counted."""
    fps = 15.0
    steps_gen = np.full(40, 2.5 / fps)
    steps_truth = np.r_[np.full(20, 2.5 / fps), np.full(20, 5.5 / fps)]
    gen = _root_and_joint(np.r_[0.0, np.cumsum(steps_gen)])
    real = _root_and_joint(np.r_[0.0, np.cumsum(steps_truth)])
    truth = GroundTruth(Takes(positions=[real]), fps=fps)
    value = evaluate(Takes(positions=[gen]), truth, metrics=["Speed Hellinger (GENEA)"]).values()
    assert value["Speed Hellinger (GENEA)"] == pytest.approx(math.sqrt(1 - math.sqrt(0.5)), rel=1e-9)


def test_published_ha2g_bc_measures_angles_between_the_mean_subtracted_vectors():
    """Bones turning about the vertical axis with a vertical mean direction m_i = (0, 0, z_i): the vectors HA2G's
    published code measured, d_i - m_i, are the horizontal parts of the bones. Built directly as unit horizontal
    vectors, they give BC (ha2g) the same value as the published variant gives on the 3-D bones."""
    sr, fps, n = 16000, 15, 60
    audio = np.zeros(4 * sr, dtype=np.float32)
    audio[[12800, 25600, 38400, 51200]] = 1.0
    phi = np.cos(np.pi * (np.arange(n) - 11.5) / 12)
    rng = np.random.default_rng(0)
    base, rate = rng.normal(size=(42, 3)), rng.uniform(0.5, 1.5, size=42)
    base /= np.linalg.norm(base, axis=-1, keepdims=True)
    angle = rate * phi[:, None]
    x, y, z = base.T
    horizontal = np.stack(
        [np.cos(angle) * x - np.sin(angle) * y, np.sin(angle) * x + np.cos(angle) * y], axis=-1
    )
    bones = np.concatenate([horizontal, np.broadcast_to(z, angle.shape)[..., None]], axis=-1)
    flat = np.concatenate([horizontal, np.zeros((n, 42, 1))], axis=-1)
    flat /= np.linalg.norm(flat, axis=-1, keepdims=True)
    mean = np.stack([np.zeros(42), np.zeros(42), z], axis=-1)
    pos = [np.zeros((n, 43, 3))]
    truth = GroundTruth(
        Takes(positions=pos, directions=[flat]),
        audio=[audio],
        change_angle=np.full(41, 0.2),  # beats drop by 0.0075 / 0.2 >= 0.03 (horizontal), 0.0038 / 0.2 (3-D)
        mean_direction=mean.ravel(),
        sr=sr,
        fps=fps,
    )
    published = evaluate(
        Takes(positions=pos, directions=[bones]), truth, metrics=["BC (ha2g published)"]
    ).values()
    by_hand = evaluate(Takes(positions=pos, directions=[flat]), truth, metrics=["BC (ha2g)"]).values()
    assert np.isfinite(by_hand["BC (ha2g)"])
    assert published["BC (ha2g published)"] == pytest.approx(by_hand["BC (ha2g)"], abs=1e-12)
    # the fixed code measures the 3-D bones, whose angles change half as much: no drop reaches 0.03, no beat
    fixed = evaluate(Takes(positions=pos, directions=[bones]), truth, metrics=["BC (ha2g)"]).values()
    assert np.isnan(fixed["BC (ha2g)"])


def test_emage_bc_of_a_drifting_sinusoid():
    """8 s at 15 fps; only the neck (TED joint 1) moves: x = sin(w t) / w + 2 t (speed 2 + cos(w t), period 1.6 s,
    always above 0.3 x the mean speed 1), minima at t = 0.8 + 1.6 k. EMAGE leaves out 2 s (30 frames) at both ends:
    beats at 0.4, 2.0 and 3.6 s after the cut (order 7 at 30 fps = 4 frames here). Audio beats 0.5, 2.0, 3.3 s:
    the neck scores mean(exp(-0.1^2/0.18), 1, exp(-0.3^2/0.18)); the 7 other EMAGE joints never move (no beat,
    0 each), so BC = that / 8."""
    fps, n = 15.0, 120
    t = np.arange(n) / fps
    w = 2 * np.pi / 1.6
    pos = np.zeros((n, 43, 3))
    pos[:, 1, 0] = np.sin(w * t) / w + 2.0 * t
    onsets = np.array([0.5, 2.0, 3.3])
    truth = GroundTruth(
        Takes(positions=[pos]),
        audio=[np.zeros(8 * 16000, np.float32)],
        mean_speed=np.ones(43),
        fps=fps,
        onsets={"BC (emage)": [onsets]},  # the onsets EMAGE's librosa call would give, set by hand
    )
    neck = (math.exp(-(0.1**2) / 0.18) + 1.0 + math.exp(-(0.3**2) / 0.18)) / 3
    value = evaluate(Takes(positions=[pos]), truth, metrics=["BC (emage)"]).get("BC (emage)").value
    assert value == pytest.approx(neck / 8, rel=1e-9)


def test_every_metric_key_names_its_variant_and_where_it_comes_from():
    from beatlite.metrics.scoring import METRICS, describe

    for key, m in METRICS.items():
        assert m.describe and len(m.source) > 40, key
        assert any(w in m.source for w in ("et al.", "code", "metric.py", "genea")), (key, m.source)
        assert m.source in describe([key], sources=True) and m.source not in describe([key]), key


# ----------------------------------------------------------------------------- edge cases a user's outputs produce
def test_equal_speed_histograms_are_exactly_0_apart_and_negative_counts_are_refused():
    from beatlite.metrics.extras import hellinger_distance

    h = np.arange(49.0)
    assert hellinger_distance(h, 3 * h) == 0.0  # sqrt(1 - sum sqrt(pq)) left 1.05e-08 here
    assert hellinger_distance(np.array([1.0, 0.0]), np.array([0.0, 1.0])) == pytest.approx(1.0, abs=1e-15)
    with pytest.raises(ValueError, match="counts >= 0"):
        hellinger_distance(np.array([-1.0, 2.0]), np.array([1.0, 1.0]))  # was 0.0, "perfect"
    with pytest.raises(ValueError, match="no value inside its bins"):
        hellinger_distance(np.zeros(49), h)


def test_zero_frames_are_refused_or_left_out_never_nan():
    empty, take = np.zeros((0, 5, 3)), np.random.default_rng(0).normal(size=(10, 5, 3))
    for metric in (pck, mpjpe):
        with pytest.raises(ValueError, match="no frames"):
            metric(empty, empty)  # was nan, with numpy's "mean of empty slice"
    assert l1_diversity([np.zeros((0, 15)), take.reshape(10, 15)]) == l1_diversity(
        take
    )  # was a reshape error


def test_batch_pairing_refuses_batches_of_other_sizes():
    """Batches of 16 and 10 rows: with every batch used the stacked shapes match, the rows paired do not."""
    rng = np.random.default_rng(0)
    batches = [rng.normal(size=(16, 8)), rng.normal(size=(10, 8))]
    with pytest.raises(ValueError, match=r"equal batch sizes, got batches of \[10, 16\] rows"):
        diversity(batches, n_pairs=2, batch_pairing=True, seed=3)


def test_a_metric_undefined_on_the_takes_is_skipped_with_its_reason():
    """No audio onset in any take: BeatAlign is NaN by definition, listed as skipped (was a NaN result)."""
    rng = np.random.default_rng(0)
    takes = Takes(positions=[np.cumsum(rng.normal(size=(60, 43, 3)), axis=0)])
    ev = evaluate(takes, GroundTruth(takes, audio_beats=[np.array([])]), metrics=["BeatAlign", "MPJPE"])
    assert [r.key for r in ev.results] == ["MPJPE"] and "no audio onset" in ev.skipped["BeatAlign"]
    assert math.isnan(ev.values()["BeatAlign"])
