"""HA2G losses and bone-angle statistics (beatlite.models.ha2g_losses): closed forms and properties."""

from __future__ import annotations

import math

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from beatlite.models.ha2g_losses import (  # noqa: E402
    N_BONES,
    angle_statistics,
    bone_angles,
    contrastive_ce,
    directions_with_palms,
    hierarchical_huber,
    multilevel_contrastive_loss,
    physical_constraint_loss,
    style_diverging_loss,
)
from beatlite.models.layers import kl_standard_normal  # noqa: E402


def _random_unit_dirs(rng: np.random.Generator, shape: tuple[int, ...]) -> np.ndarray:
    v = rng.standard_normal((*shape, N_BONES, 3))
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


# ----------------------------------------------------------------------------- contrastive
def test_contrastive_hand_computed_two_rows() -> None:
    # Rows q1 = (1, 0), q2 = (0, 1); keys equal to the queries. Distances: 0 on the diagonal
    # (floored at min_distance = 0.5 -> logit 2) and sqrt(2) off it (logit 1/sqrt(2)).
    # CE per row = -log(e^2 / (e^2 + e^{1/sqrt 2})) = log(1 + e^{1/sqrt 2 - 2}).
    q = torch.tensor([[[1.0, 0.0], [0.0, 1.0]]])  # (B=1, T=2, F=2)
    expected = math.log1p(math.exp(1 / math.sqrt(2) - 2))
    got = contrastive_ce(q, q.clone(), min_distance=0.5)
    assert float(got) == pytest.approx(expected, rel=1e-6)
    # Swapped keys: the correct class now has logit 1/sqrt(2), the wrong one 2.
    swapped = q[:, [1, 0]]
    expected_swapped = math.log1p(math.exp(2 - 1 / math.sqrt(2)))
    assert float(contrastive_ce(q, swapped, min_distance=0.5)) == pytest.approx(expected_swapped, rel=1e-6)


def test_contrastive_minimal_when_matched_larger_when_shuffled() -> None:
    g = torch.Generator().manual_seed(0)
    text = torch.randn(4, 34, 16, generator=g)
    matched = contrastive_ce(text, text.clone())
    perm = torch.randperm(4 * 34, generator=g)
    shuffled = text.reshape(-1, 16)[perm].reshape(4, 34, 16)
    other = torch.randn(4, 34, 16, generator=g)
    assert float(matched) < 1e-3  # diagonal logit 1/0.01 = 100 dominates every row
    assert float(contrastive_ce(text, shuffled)) > 10.0
    assert float(contrastive_ce(text, other)) > float(matched) + 1.0
    # scale invariance: features are L2-normalised first
    assert float(contrastive_ce(3.0 * text, text)) == pytest.approx(float(matched), abs=1e-6)


def test_multilevel_contrastive_uses_the_named_levels() -> None:
    g = torch.Generator().manual_seed(1)
    text = torch.randn(2, 34, 8, generator=g)
    audio = {"low": torch.randn(2, 34, 8, generator=g), "high": text.clone()}
    out = multilevel_contrastive_loss(text, audio)
    assert float(out["positive"]) < 1e-3 < float(out["negative"])
    with pytest.raises(KeyError, match="mid"):
        multilevel_contrastive_loss(text, audio, positive="mid")


def test_contrastive_rejects_mismatched_shapes() -> None:
    with pytest.raises(ValueError, match="query and key"):
        contrastive_ce(torch.zeros(2, 34, 8), torch.zeros(2, 33, 8))


# ----------------------------------------------------------------------------- KL, Huber, style
def test_kl_zero_at_standard_normal_and_closed_form() -> None:
    zeros = torch.zeros(3, 16)
    assert float(kl_standard_normal(zeros, zeros)) == 0.0
    # mu = 1, logvar = 0: -0.5 (1 + 0 - 1 - 1) = 0.5 per dimension.
    assert float(kl_standard_normal(torch.ones(3, 16), zeros)) == pytest.approx(0.5)
    # mu = 0, logvar = log 2: -0.5 (1 + ln 2 - 2) = 0.5 (1 - ln 2).
    lv = torch.full((3, 16), math.log(2.0))
    assert float(kl_standard_normal(zeros, lv)) == pytest.approx(0.5 * (1 - math.log(2.0)), rel=1e-6)


def test_hierarchical_huber_zero_on_perfect_prediction_and_hand_values() -> None:
    targets = [torch.randn(2, 34, 24), torch.randn(2, 34, 126)]
    assert float(hierarchical_huber([t.clone() for t in targets], targets)) == 0.0
    # level 1: every error 0.05 < beta = 0.1 -> 0.5 * 0.05^2 / 0.1 = 0.0125;
    # level 2: every error 1.0 -> 1.0 - 0.5 * 0.1 = 0.95; the levels are summed.
    preds = [targets[0] + 0.05, targets[1] - 1.0]
    assert float(hierarchical_huber(preds, targets)) == pytest.approx(0.0125 + 0.95, rel=1e-4)


def test_style_diverging_loss_zero_for_identical_outputs_and_clipped() -> None:
    pose = torch.randn(4, 34, 126)
    z, z2 = torch.zeros(4, 8), torch.ones(4, 8)
    assert float(style_diverging_loss(pose, pose.clone(), z, z2)) == 0.0
    # one clip differing by 1.0 everywhere: Huber_0.05 = 1 - 0.025 per value, summed over 34*126,
    # divided by mean|z - z2| + 1e-5 = 1.00001; clipped at 1000 for every clip.
    far = pose + 1.0
    assert float(style_diverging_loss(pose, far, z, z2)) == pytest.approx(-1000.0)
    small = pose.clone()
    small[0] += 0.01  # 0.5 * 0.01^2 / 0.05 = 0.001 per value -> 4.284 / 1.00001, averaged over 4 clips
    expected = -(34 * 126 * 0.001 / 1.00001) / 4
    assert float(style_diverging_loss(pose, small, z, z2)) == pytest.approx(expected, rel=1e-4)


# ----------------------------------------------------------------------------- angles, physical
def test_palm_normals_are_unit_cross_products() -> None:
    rng = np.random.default_rng(2)
    u = _random_unit_dirs(rng, (5,))
    mean = u.mean(axis=0).reshape(-1)
    dirvec = torch.as_tensor(u.reshape(5, -1) - mean, dtype=torch.float64)
    v = directions_with_palms(dirvec, torch.as_tensor(mean)).numpy()
    assert v.shape == (5, 44, 3)
    np.testing.assert_allclose(v[:, :42], u, atol=1e-12)
    left = np.cross(u[:, 11], u[:, 17])
    np.testing.assert_allclose(v[:, 42], left / np.linalg.norm(left, axis=-1, keepdims=True), atol=1e-12)
    right = np.cross(u[:, 28], u[:, 34])
    np.testing.assert_allclose(v[:, 43], right / np.linalg.norm(right, axis=-1, keepdims=True), atol=1e-12)


def test_bone_angles_hand_values_and_numpy_oracle() -> None:
    from beatlite.metrics.beats import append_palm_normals, included_angles

    u = np.zeros((1, N_BONES, 3))
    u[:, :, 0] = 1.0
    u[0, 1] = [0.0, 1.0, 0.0]  # 90 degrees from bone 0 -> 0.5 (units of pi)
    u[0, 2] = [-1.0, 0.0, 0.0]  # anti-parallel to bone 0 -> ~1 (cosine clamped at 1 - 1e-6)
    pairs = torch.tensor([[0, 1], [0, 2], [0, 3]])
    mean = torch.zeros(126, dtype=torch.float64)
    theta = bone_angles(torch.as_tensor(u.reshape(1, -1)), mean, pairs).numpy()[0]
    assert theta[0] == pytest.approx(0.5)
    assert theta[1] == pytest.approx(1.0, abs=1e-3)
    assert theta[2] == pytest.approx(0.0, abs=1e-3)
    # the metrics module's numpy implementation agrees on random poses (palm normals included)
    rng = np.random.default_rng(3)
    r = _random_unit_dirs(rng, (7,))
    all_pairs = np.array([[0, 1], [3, 4], [4, 42], [21, 43], [11, 17], [37, 38]])
    ours = bone_angles(torch.as_tensor(r.reshape(7, -1)), mean, torch.as_tensor(all_pairs)).numpy()
    ref = included_angles(append_palm_normals(r), all_pairs)
    np.testing.assert_allclose(ours, ref, atol=1e-5)


def test_angle_statistics_of_a_known_distribution() -> None:
    # Bone 1 alternates between 0 and 90 degrees from bone 0 frame by frame:
    # angles 0, 0.5, 0, 0.5 (units of pi) -> mean 0.25, variance 0.0625, mean |change| 0.5.
    u = np.zeros((2, 4, N_BONES, 3))
    u[..., 0] = 1.0
    u[:, 1::2, 1] = [0.0, 1.0, 0.0]
    mean = u.reshape(-1, 126).mean(axis=0)
    stats = angle_statistics(u.reshape(2, 4, 126) - mean, mean, pairs=np.array([[0, 1], [0, 2]]))
    np.testing.assert_allclose(stats.mean, [0.25, 0.0], atol=1e-9)
    np.testing.assert_allclose(stats.var, [0.0625, 1e-5], atol=1e-9)  # the second pair is floored
    np.testing.assert_allclose(stats.change, [0.5, 0.0], atol=1e-9)


def test_angle_statistics_of_chunks_pool_to_those_of_the_whole_array() -> None:
    # A window store is read in chunks: Chan's pooled mean / variance and the pooled change agree with
    # one pass over the whole array to float64 rounding (sums of ~1e3 terms of size <= 1: 1e-12 relative).
    rng = np.random.default_rng(7)
    d = 0.3 * rng.standard_normal((13, 6, 126))
    mean = rng.standard_normal(126)
    whole = angle_statistics(d, mean)
    pooled = angle_statistics((d[a:b] for a, b in ((0, 1), (1, 6), (6, 13))), mean)
    for field in ("mean", "var", "change"):
        np.testing.assert_allclose(getattr(pooled, field), getattr(whole, field), rtol=1e-12, atol=1e-15)
    once = angle_statistics(iter([d]), mean)  # one chunk: the very same numbers
    assert all(np.array_equal(getattr(once, f), getattr(whole, f)) for f in ("mean", "var", "change"))


def test_physical_constraint_minimal_at_the_mean_angles() -> None:
    rng = np.random.default_rng(4)
    pose = _random_unit_dirs(rng, (1,))
    train = np.repeat(pose, 6, axis=0) + 0.01 * rng.standard_normal((6, N_BONES, 3))
    train /= np.linalg.norm(train, axis=-1, keepdims=True)
    mean = train.reshape(6, -1).mean(axis=0)
    pairs = np.array([[0, 1], [1, 3], [3, 4], [4, 42], [21, 43]])
    stats = angle_statistics(train.reshape(1, 6, 126) - mean, mean, pairs=pairs)
    # Loss as a function of the angles: 0 at the mean, grows quadratically away from it.
    mu = torch.as_tensor(stats.mean)
    var = torch.as_tensor(stats.var)
    assert float(physical_constraint_loss(mu[None].clone(), mu, var)) == 0.0
    step = torch.zeros_like(mu)
    step[2] = 0.01
    # one pair off by 0.01: 0.01^2 / (2 var_2)
    expected = 0.01**2 / (2 * stats.var[2])
    assert float(physical_constraint_loss((mu + step)[None], mu, var)) == pytest.approx(expected, rel=1e-9)
    # through bone_angles: the training frames score lower than random poses
    m = torch.as_tensor(mean)
    tp = torch.as_tensor(pairs)
    train_loss = physical_constraint_loss(
        bone_angles(torch.as_tensor(train.reshape(6, -1) - mean), m, tp), mu, var
    )
    rand = _random_unit_dirs(rng, (6,)).reshape(6, -1) - mean
    rand_loss = physical_constraint_loss(bone_angles(torch.as_tensor(rand), m, tp), mu, var)
    assert float(train_loss) < float(rand_loss)


def test_angle_statistics_validates_shapes() -> None:
    with pytest.raises(ValueError, match=r"dirvec_windows must be \(N >= 1, T >= 2, 126\)"):
        angle_statistics(np.zeros((3, 34, 120)), np.zeros(126))
    with pytest.raises(ValueError, match=r"mean_dirvec must be \(126,\)"):
        angle_statistics(np.zeros((3, 34, 126)), np.zeros(125))
