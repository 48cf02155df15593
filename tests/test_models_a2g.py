"""A2G (Audio2Gestures-style conditional VAE): shapes, the VAE parts, loss terms, gradients, determinism."""

from __future__ import annotations

import math

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from beatlite.models import build_model  # noqa: E402
from beatlite.models.a2g import kl_standard_normal, reparameterize  # noqa: E402
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
    for key in ("z_audio", "z_pose"):
        assert out[key].shape == (3, 34, s), key
    for key in ("mu", "logvar", "eps", "eps_rec"):
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


def test_reparameterisation_moments_and_gradient():
    mu = torch.tensor([0.5, -1.0], requires_grad=True)
    logvar = torch.tensor([0.0, math.log(4.0)], requires_grad=True)
    noise = torch.randn(200_000, 2, generator=torch.Generator().manual_seed(1))
    z = reparameterize(mu, logvar, noise)
    # sample mean within 5 standard errors (sd / sqrt(n)) of mu; sample sd within 1 % of exp(logvar / 2)
    sd = torch.tensor([1.0, 2.0])
    assert torch.all((z.mean(0) - mu).abs() < 5 * sd / math.sqrt(len(noise)))
    np.testing.assert_allclose(z.std(0).detach().numpy(), sd.numpy(), rtol=0.01)
    assert torch.equal(reparameterize(mu, logvar, torch.zeros(2)), mu)
    # dz/dmu = 1, dz/dlogvar = exp(logvar / 2) * noise / 2
    eps = torch.tensor([0.3, -0.7])
    reparameterize(mu, logvar, eps).sum().backward()
    np.testing.assert_allclose(mu.grad.numpy(), [1.0, 1.0])
    np.testing.assert_allclose(logvar.grad.numpy(), (0.5 * sd * eps).numpy(), rtol=1e-6)


def test_loss_terms_on_hand_cases(batch):
    model = _model(relaxed_margin=0.5)
    target = batch["pose"]
    b, t, _ = target.shape
    s, m = model.config.shared_dim, model.config.specific_dim
    codes = torch.randn(b, t, s)
    eps = torch.randn(b, t, m)
    out = {
        "pose": target + 0.7,
        "pose_motion": target,
        "pose_cross": target + 0.25,
        "z_audio": codes,
        "z_pose": codes,
        "mu": torch.ones(b, t, m),
        "logvar": torch.zeros(b, t, m),
        "eps": eps,
        "eps_rec": eps,
    }
    parts = model.losses(batch, out, epoch=0)
    assert float(parts["rec"]) == 0.0 and float(parts["shared"]) == 0.0 and float(parts["bicycle"]) == 0.0
    assert float(parts["cross"]) == pytest.approx(0.25, rel=1e-5)
    assert float(parts["kld"]) == pytest.approx(0.5)
    assert float(parts["relaxed"]) == pytest.approx(0.7 - 0.5, rel=1e-5)  # the margin is free
    cfg = model.config
    assert float(parts["total"]) == pytest.approx(
        cfg.cross_weight * 0.25 + cfg.kld_weight * 0.5 + cfg.relaxed_weight * 0.2, rel=1e-5
    )
    within = dict(out, pose=target - 0.3)
    assert float(model.losses(batch, within, epoch=0)["relaxed"]) == 0.0


def test_bicycle_and_kl_train_the_right_parts(batch):
    model = _model()
    out = model(batch)
    model.losses(batch, out, epoch=0)["bicycle"].backward()
    # the random code must be recoverable from its motion: decoder and motion encoder learn from it
    for module in (model.decoder, model.motion_encoder, model.audio_head):
        assert all(float(p.grad.abs().sum()) > 0 for p in module.parameters())
    model.zero_grad()
    out = model(batch)
    model.losses(batch, out, epoch=0)["kld"].backward()
    assert all(float(p.grad.abs().sum()) > 0 for p in model.motion_encoder.parameters())
    assert all(p.grad is None or float(p.grad.abs().sum()) == 0 for p in model.decoder.parameters())


def test_generation_reads_audio_only_and_is_deterministic(batch):
    model = _model().eval()
    out = model(batch)["pose"]
    assert torch.equal(model(batch)["eps"], torch.zeros(3, 34, model.config.specific_dim))
    other = dict(batch)
    other["pose"] = torch.randn_like(batch["pose"])
    assert torch.equal(model(other)["pose"], out)
    assert torch.equal(model.generate(batch), out)
    other["audio"] = batch["audio"] * 0.5
    assert not torch.allclose(model(other)["pose"], out)
    model.train()
    torch.manual_seed(5)
    a = model(batch)["pose"]
    torch.manual_seed(5)
    assert torch.equal(model(batch)["pose"], a)
    assert not torch.equal(model(batch)["pose"], a)  # a fresh eps draw


def test_sampled_generation_is_seeded(batch):
    a, b = _model(eval_z="sample", seed=7).eval(), _model(eval_z="sample", seed=7).eval()
    first = a.generate(batch)
    assert torch.equal(b.generate(batch), first)
    second = a.generate(batch)
    assert not torch.equal(second, first)
    a.reset()
    assert torch.equal(a.generate(batch), first)
    mean = _model().eval()
    assert not torch.equal(mean.generate(batch), first)


def test_config_validation_and_missing_audio(batch):
    model = _model().eval()
    with pytest.raises(ValueError, match="eval_z"):
        _model(eval_z="median")
    with pytest.raises(KeyError, match="audio"):
        model({"pose": batch["pose"]})


def test_paper_preset_builds_and_runs(batch):
    torch.manual_seed(0)
    model = build_model("a2g", preset="paper").eval()
    assert model.config.hidden == 256
    assert model(batch)["pose"].shape == (3, 34, 141)
