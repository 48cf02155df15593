"""A2G (the authors' Audio2Gestures code): shapes, the VAE parts, loss terms, sampling, parameter count."""

from __future__ import annotations

import math

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from beatlite.models import build_model  # noqa: E402
from beatlite.models.a2g import kl_reference, kl_schedule  # noqa: E402
from beatlite.models.layers import kl_standard_normal, reparameterize  # noqa: E402
from beatlite.models.testing import fake_batch  # noqa: E402


@pytest.fixture(scope="module")
def batch():
    return fake_batch(3)


def _model(torch_seed: int = 0, **kw):
    torch.manual_seed(torch_seed)
    return build_model("a2g", preset="tiny", **kw)


def test_shapes(batch):
    model = _model()
    out = model(batch)
    s, m = model.config.shared_dim, model.config.specific_dim
    for key in ("pose", "pose_motion", "pose_cross"):
        assert out[key].shape == (3, 34, 141), key
    for key in ("z_audio", "z_pose", "z_x_share", "audio_mu", "share_logvar"):
        assert out[key].shape == (3, 34, s), key
    for key in ("z_m", "z_x", "z_x_spec", "spec_mu", "map_logvar"):
        assert out[key].shape == (3, 34, m), key


def test_kl_closed_form_on_hand_cases_and_against_torch():
    zeros = torch.zeros(2, 5)
    assert float(kl_standard_normal(zeros, zeros)) == 0.0
    # mu = 1, var = 1: KL = mu^2 / 2 = 0.5
    assert float(kl_standard_normal(torch.ones(2, 5), zeros)) == pytest.approx(0.5)
    # mu = 0, var = 2: KL = (var - 1 - log var) / 2
    logvar = torch.full((2, 5), math.log(2.0))
    assert float(kl_standard_normal(zeros, logvar)) == pytest.approx((2 - 1 - math.log(2)) / 2, rel=1e-6)
    gen = torch.Generator().manual_seed(0)
    mu, logvar = torch.randn(4, 7, generator=gen), torch.randn(4, 7, generator=gen)
    dist = torch.distributions
    oracle = dist.kl_divergence(dist.Normal(mu, torch.exp(0.5 * logvar)), dist.Normal(0.0, 1.0)).mean()
    assert float(kl_standard_normal(mu, logvar)) == pytest.approx(float(oracle), rel=1e-5)


def test_reference_kl_sums_over_frames_and_schedule():
    # (B, T, C) = (2, 5, 3), mu = 1, var = 1: 0.5 per element, summed over T = 5 frames -> 2.5
    assert float(kl_reference(torch.ones(2, 5, 3), torch.zeros(2, 5, 3))) == pytest.approx(2.5)
    # the reference's factor: (step // 10) % 10000 * 1e-4, at least 1e-4
    assert [kl_schedule(s) for s in (0, 9, 10, 99_999)] == pytest.approx([1e-4, 1e-4, 1e-4, 0.9999])
    assert kl_schedule(100_010) == pytest.approx(1e-4)


def test_reparameterisation_moments_and_gradient():
    mu = torch.tensor([0.5, -1.0], requires_grad=True)
    logvar = torch.tensor([0.0, math.log(4.0)], requires_grad=True)
    noise = torch.randn(200_000, 2, generator=torch.Generator().manual_seed(1))
    z = reparameterize(mu, logvar, noise)
    sd = torch.tensor([1.0, 2.0])
    assert torch.all((z.mean(0) - mu).abs() < 5 * sd / math.sqrt(len(noise)))
    np.testing.assert_allclose(z.std(0).detach().numpy(), sd.numpy(), rtol=0.01)
    eps = torch.tensor([0.3, -0.7])
    reparameterize(mu, logvar, eps).sum().backward()
    np.testing.assert_allclose(mu.grad.numpy(), [1.0, 1.0])
    np.testing.assert_allclose(logvar.grad.numpy(), (0.5 * sd * eps).numpy(), rtol=1e-6)


def test_loss_terms_on_hand_cases(batch):
    model = build_model("a2g", preset="paper", tolerance=0.5)
    target = batch["pose"]
    b, t, _ = target.shape
    s, m = model.config.shared_dim, model.config.specific_dim
    codes, spec = torch.randn(b, t, s), torch.randn(b, t, m)
    ramp = 0.1 * torch.arange(t, dtype=torch.float32).view(1, t, 1)
    zero_s, zero_m = torch.zeros(b, t, s), torch.zeros(b, t, m)
    out = {
        "pose": target + 0.7 * torch.sign(torch.randn_like(target)),  # |error| 0.7 > tolerance everywhere
        "pose_motion": target,
        "pose_cross": target + ramp,  # error 0.1 k at frame k, speed error 0.1
        "z_audio": codes, "z_pose": codes, "z_m": spec, "z_x": spec, "z_x_spec": spec, "z_x_share": codes,
        "audio_mu": zero_s, "audio_logvar": zero_s, "share_mu": zero_s, "share_logvar": zero_s,
        "spec_mu": torch.ones(b, t, m), "spec_logvar": zero_m, "map_mu": zero_m, "map_logvar": zero_m,
    }  # fmt: skip
    parts = model.losses(batch, out, epoch=0)
    for key in (
        "rec",
        "rec_speed",
        "code",
        "cycle_spec",
        "cycle_share",
        "kl_audio",
        "kl_share",
        "kl_mapping",
    ):
        assert float(parts[key]) == 0.0, key
    assert float(parts["cross"]) == pytest.approx(0.1 * (t - 1) / 2, rel=1e-5)
    assert float(parts["cross_speed"]) == pytest.approx(0.1, rel=1e-4)
    assert float(parts["relaxed"]) == pytest.approx(0.7, rel=1e-5)
    assert float(parts["kl_spec"]) == pytest.approx(0.5 * t, rel=1e-6)
    diverse = -float((out["pose"] - out["pose_cross"]).abs().mean())
    assert float(parts["diverse"]) == pytest.approx(diverse, rel=1e-6)
    relaxed_speed = float(
        (out["pose"][:, 1:] - out["pose"][:, :-1] - target[:, 1:] + target[:, :-1]).abs().mean()
    )
    # start.sh's weights; step 0: KL factor 1e-4, diversity weight 0.1
    expected = (
        0.1 * (t - 1) / 2 + 0.1 + 0.7 + 5 * relaxed_speed + 1e-3 * 1e-4 * 0.5 * t + 0.1 * diverse
    )  # fmt: skip
    assert float(parts["total"]) == pytest.approx(expected, rel=1e-5)
    # the relaxed loss averages only the elements beyond the tolerance
    half = dict(out, pose=target + torch.where(torch.arange(141) < 47, 0.9, 0.2))
    assert float(model.losses(batch, half, epoch=0)["relaxed"]) == pytest.approx(0.9, rel=1e-5)


def test_training_counts_steps_and_stores_code_statistics(batch):
    model = _model()
    assert int(model.steps) == 0 and int(model.n_stats) == 0
    out = model(batch)
    model.losses(batch, out, epoch=0)
    assert int(model.steps) == 1 and int(model.n_stats) == 3
    z_m = out["z_m"].detach()
    torch.testing.assert_close(model.spec_stats[:3, 0], z_m.mean(1))
    torch.testing.assert_close(model.spec_stats[:3, 1], z_m.std(1))
    model.eval()
    model.losses(batch, model(batch), epoch=0)
    assert int(model.steps) == 1 and int(model.n_stats) == 3  # evaluation changes neither


def test_generation_reads_audio_only(batch):
    model = _model()
    model(batch)  # one training pass: statistics to sample from
    model.eval()
    out = model.generate(batch)
    other = dict(batch)
    other["pose"] = torch.randn_like(batch["pose"])
    assert torch.equal(model.reset() or model.generate(other), out)
    other["mel"] = batch["mel"] * 0.5
    model.reset()
    assert not torch.allclose(model.generate(other), out)


def test_sampled_generation_is_seeded_and_mean_is_an_option(batch):
    a, b = _model(seed=7), _model(seed=7)
    for m in (a, b):
        torch.manual_seed(1)
        m(batch)
        m.eval()
    first = a.generate(batch)
    assert torch.equal(b.generate(batch), first)
    second = a.generate(batch)
    assert not torch.equal(second, first)  # the next call draws again
    a.reset()
    assert torch.equal(a.generate(batch), first)
    c = _model(seed=8)
    torch.manual_seed(1)
    c(batch)
    assert not torch.equal(c.eval().generate(batch), first)
    mean = _model(eval_z="mean")
    torch.manual_seed(1)
    mean(batch)
    mean.eval()
    out = mean(batch)
    assert torch.equal(out["z_audio"], out["audio_mu"]) and torch.equal(out["z_x"], out["map_mu"])
    assert torch.equal(mean(batch)["pose"], out["pose"])  # deterministic


def test_config_validation_and_missing_mel(batch):
    model = _model().eval()
    with pytest.raises(ValueError, match="eval_z"):
        _model(eval_z="median")
    with pytest.raises(KeyError, match="mel"):
        model({"pose": batch["pose"]})
    with pytest.raises(ValueError, match="mel"):
        model({"pose": batch["pose"], "mel": batch["mel"][..., :64]})


def _conv(c_in: int, c_out: int, k: int) -> int:
    return c_in * c_out * k + c_out


def _tcn(c_in: int, widths: list[int]) -> int:
    """module.py ConvNet: per level two k3 convolutions and a 1x1 downsample where the width changes."""
    total = 0
    for c_out in widths:
        total += (
            _conv(c_in, c_out, 3) + _conv(c_out, c_out, 3) + (_conv(c_in, c_out, 1) if c_in != c_out else 0)
        )
        c_in = c_out
    return total


def reference_count(audio_size: int, pose_dim: int, audio_hidden: int = 16, pose_hidden: int = 16) -> int:
    """JingLi513/Audio2Gestures model.py: Audio_Enc + Motion_Enc + Motion_Dec + MappingNet, from its layer shapes."""
    audio = _tcn(audio_size, [128, 128, 96, 96, 64]) + 2 * (_conv(64, 32, 1) + _conv(32, audio_hidden, 1))
    motion = (
        _tcn(pose_dim, [256, 256, 128, 128, 64]) + 2 * _conv(64, 32, 1)  # share_linear, spec_linear
        + 2 * (_conv(32, 32, 1) + _conv(32, pose_hidden, 1))  # share_mean, share_var
        + 2 * (_conv(32, 32, 1) + _conv(32, pose_hidden, 1))  # spec_mean, spec_var
    )  # fmt: skip
    decoder = (
        _tcn(audio_hidden + pose_hidden, [64, 128, 128, 256, 256])
        + _conv(256, 256, 1)
        + _conv(256, pose_dim, 1)
    )
    mapping = 3 * _conv(pose_hidden, pose_hidden, 3) + 4 * _conv(pose_hidden, pose_hidden, 1)
    return audio + motion + decoder + mapping


def test_paper_preset_has_the_reference_parameter_count(batch):
    torch.manual_seed(0)
    model = build_model("a2g", preset="paper")
    cfg = model.config
    assert (cfg.shared_dim, cfg.specific_dim, cfg.init_std, cfg.xspeed_weight) == (16, 16, 0.01, 5.0)
    # 128 log-mel bands in (the reference: 64), 141 Euler channels out (the reference: 22 joints x 6)
    assert model.n_parameters() == reference_count(128, 141)
    assert model.eval()(batch)["pose"].shape == (3, 34, 141)


def test_tiny_uses_the_code_means_and_freezes_the_unused_log_variances(batch):
    model = _model()
    assert not model.config.vae and model.config.speed_weight == model.config.xspeed_weight == 0
    out = model(batch)
    assert torch.equal(out["z_audio"], out["audio_mu"]) and torch.equal(out["z_m"], out["spec_mu"])
    assert torch.equal(out["z_x"], out["map_mu"])
    frozen = [n for n, p in model.named_parameters() if not p.requires_grad]
    assert frozen and all(".logvar." in n for n in frozen)
    parts = {k: v.detach() for k, v in model.losses(batch, out, epoch=0).items()}
    assert float(parts["total"] - sum(parts[k] for k in ("rec", "cross", "relaxed"))) == pytest.approx(
        float(0.1 * (parts["code"] + parts["cycle_spec"] + parts["cycle_share"]) + 0.1 * parts["diverse"]),
        rel=1e-5,
    )


def test_the_recipes_and_shipped_checkpoints_evaluate_with_sampled_codes():
    from beatlite.paths import checkpoints_dir
    from beatlite.train.checkpoint import load_checkpoint
    from beatlite.train.recipes import RECIPES

    for name in ("a2g_tiny", "joint_embedding_tiny"):
        recipe = RECIPES[name]
        assert build_model(recipe.model, preset="tiny", **recipe.overrides).config.eval_z == "sample", name
        path = checkpoints_dir() / f"{name}.pt"
        if path.is_file():
            assert load_checkpoint(path)["model"]["eval_z"] == "sample", name
