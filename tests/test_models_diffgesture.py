"""DiffGesture: the forward process, the samplers with an oracle denoiser, guidance, seeding (values derived here)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

from beatlite.models import build_model
from beatlite.models.diffgesture import NoiseSchedule, ddim_sample, ddpm_sample
from beatlite.models.testing import fake_batch


def _alpha_bars(steps: int, beta_1: float, beta_T: float) -> np.ndarray:
    """abar_0..abar_T computed here from the definition (numpy, float64)."""
    betas = np.linspace(beta_1, beta_T, steps)
    return np.concatenate([[1.0], np.cumprod(1.0 - betas)])


def _model(**overrides: object) -> torch.nn.Module:
    torch.manual_seed(0)
    return build_model("diffgesture", preset="tiny", **overrides).eval()


def _batch(b: int = 3, seed: int = 0) -> dict[str, torch.Tensor]:
    full = fake_batch(b, seed=seed)
    return {"dirvec": full["dirvec"], "audio": full["audio"]}


def test_closed_form_moments_equal_the_iterated_kernel() -> None:
    """Iterating q(x_t | x_{t-1}) = N(sqrt(alpha_t) x, beta_t): the mean factor and the variance of x_t | x_0."""
    sched = NoiseSchedule(500, 1e-4, 0.02)
    betas = np.linspace(1e-4, 0.02, 500)
    mean, var = 1.0, 0.0
    for t in range(1, 501):
        mean, var = mean * math.sqrt(1.0 - betas[t - 1]), (1.0 - betas[t - 1]) * var + betas[t - 1]
        ab = float(sched.alpha_bars[t])
        assert mean == pytest.approx(math.sqrt(ab), rel=1e-12) and var == pytest.approx(1.0 - ab, rel=1e-12)
    assert float(sched.alpha_bars[0]) == 1.0 and float(sched.betas[0]) == 0.0


def test_q_sample_and_the_iterated_kernel_draw_the_same_distribution() -> None:
    """Monte Carlo with n = 40000 draws: sample means within 5 standard errors (sqrt(v / n)) and sample
    variances within 5 of theirs (v sqrt(2 / (n - 1))) of the closed form, for both routes."""
    sched, n, t = NoiseSchedule(100, 1e-3, 0.05), 40_000, 60
    x0 = torch.tensor([1.5, -0.7, 0.0], dtype=torch.float64).expand(n, 3)
    g = torch.Generator().manual_seed(0)
    x = x0.clone()
    for s in range(1, t + 1):
        x = sched.q_step(x, torch.full((n,), s), torch.randn(x.shape, generator=g, dtype=torch.float64))
    closed = sched.q_sample(x0, torch.full((n,), t), torch.randn(x0.shape, generator=g, dtype=torch.float64))
    ab = _alpha_bars(100, 1e-3, 0.05)[t]
    want_mean, want_var = math.sqrt(ab) * x0[0].numpy(), 1.0 - ab
    for draws in (x, closed):
        d = draws.numpy()
        assert np.all(np.abs(d.mean(0) - want_mean) < 5 * math.sqrt(want_var / n))
        assert np.all(np.abs(d.var(0, ddof=1) - want_var) < 5 * want_var * math.sqrt(2 / (n - 1)))


def _oracle(x0: torch.Tensor, steps: int = 500) -> object:
    """eps(x_t, t) = the noise that takes x0 to x_t (abar from the definition)."""
    ab = _alpha_bars(steps, 1e-4, 0.02)

    def eps(x: torch.Tensor, t: int) -> torch.Tensor:
        reps = x.shape[0] // x0.shape[0]
        return (x - math.sqrt(ab[t]) * x0.repeat(reps, 1, 1)) / math.sqrt(1.0 - ab[t])

    return eps


@pytest.mark.parametrize("dtype", [torch.float64, torch.float32])
def test_an_oracle_denoiser_makes_ddpm_and_ddim_recover_the_clean_window(dtype: torch.dtype) -> None:
    sched = NoiseSchedule(500, 1e-4, 0.02)
    g = torch.Generator().manual_seed(1)
    x0 = 0.3 * torch.randn(2, 34, 126, generator=g, dtype=dtype)
    x_T = torch.randn(x0.shape, generator=g, dtype=dtype)
    got = ddpm_sample(sched, _oracle(x0), x_T, generator=g, stabilizer_t0=25)
    assert (got - x0).abs().max() < 1e-5
    for steps in (1, 7, 50, 500):
        for eta in (0.0, 1.0):
            got = ddim_sample(sched, _oracle(x0), x_T, steps=steps, eta=eta, generator=g, stabilizer_t0=25)
            assert (got - x0).abs().max() < 1e-5, (steps, eta)


@pytest.mark.parametrize("sampler", ["ddpm", "ddim"])
def test_the_model_samples_the_clean_window_with_an_oracle_network(sampler: str, monkeypatch) -> None:  # noqa: ANN001
    """Through ``generate`` (guidance, seeding, float32): the network replaced by the oracle."""
    model, batch = _model(diffusion_steps=500, prediction="eps", x_scale=1.0), _batch()
    x0 = 0.3 * torch.randn(3, 34, 126, generator=torch.Generator().manual_seed(2))
    oracle = _oracle(x0)
    monkeypatch.setattr(model, "denoise", lambda x, t, cond: oracle(x, int(t[0])))
    got = model.generate(batch, sampler=sampler, guidance_scale=1.15)
    assert got.dtype == torch.float32 and (got - x0).abs().max() < 1e-5


@pytest.mark.parametrize("sampler", ["ddpm", "ddim"])
def test_an_x0_predicting_oracle_on_scaled_windows_samples_the_clean_window(
    sampler: str, monkeypatch
) -> None:  # noqa: ANN001
    """``prediction="x0"``, ``x_scale=3``: a network that returns the (scaled) clean window gives it back."""
    model, batch = _model(prediction="x0", x_scale=3.0), _batch()
    x0 = 0.3 * torch.randn(3, 34, 126, generator=torch.Generator().manual_seed(2))
    monkeypatch.setattr(model, "denoise", lambda x, t, cond: 3.0 * x0.repeat(x.shape[0] // 3, 1, 1))
    got = model.generate(batch, sampler=sampler, guidance_scale=1.15)
    assert (got - x0).abs().max() < 1e-5
    # clipping the estimate at +-0.6 (diffused units): DDIM's last step returns the clipped window exactly
    model.config.clip_x0 = 0.6
    got = model.generate(batch, sampler="ddim", guidance_scale=1.15)
    assert (got - (3.0 * x0).clamp(-0.6, 0.6) / 3.0).abs().max() < 1e-5


def test_the_training_pass_noises_and_denoises_consistently(monkeypatch) -> None:  # noqa: ANN001
    """With the oracle as the network, the loss is 0 and the predicted clean window is the target."""
    model, batch = _model(prediction="eps", x_scale=1.0), _batch()
    x0 = batch["dirvec"].double()
    ab = torch.as_tensor(_alpha_bars(500, 1e-4, 0.02))

    def oracle(x: torch.Tensor, t: torch.Tensor, cond: torch.Tensor) -> torch.Tensor:
        a = ab[t].view(-1, 1, 1)
        return ((x.double() - a.sqrt() * x0) / (1.0 - a).sqrt()).float()

    monkeypatch.setattr(model, "denoise", oracle)
    model.train()
    out = model(batch)
    assert model.losses(batch, out, epoch=0)["total"] < 1e-10
    assert (out["pose"] - batch["dirvec"]).abs().max() < 1e-4
    assert out["t"].min() >= 1 and out["t"].max() <= 500


def test_the_x0_training_pass_regresses_the_scaled_clean_window(monkeypatch) -> None:  # noqa: ANN001
    model, batch = _model(prediction="x0", x_scale=3.0), _batch()
    monkeypatch.setattr(model, "denoise", lambda x, t, cond: 3.0 * batch["dirvec"])
    model.train()
    out = model(batch)
    assert model.losses(batch, out, epoch=0)["total"] < 1e-12 and set(model.losses(batch, out, epoch=0)) == {
        "x0",
        "total",
    }
    assert (out["pose"] - batch["dirvec"]).abs().max() < 1e-6
    # the noise it implies is the noise that was added (x_t = sqrt(abar) 3 x0 + sqrt(1 - abar) noise)
    assert (out["eps"] - out["noise"]).abs().max() < 1e-3


@torch.no_grad()
def test_x0_guidance_combines_the_clean_window_estimates() -> None:
    model, batch = _model(prediction="x0", x_scale=3.0), _batch()
    cond = model.condition(batch)
    x = torch.randn(3, 34, 126, generator=torch.Generator().manual_seed(3))
    t = torch.full((3,), 123)
    x0_u = model.denoise(x, t, model.null_condition.expand_as(cond))
    x0_c = model.denoise(x, t, cond)
    want = model.schedule.predict_eps(x, t, x0_u + 2.0 * (x0_c - x0_u))
    assert torch.allclose(model.guided_eps(x, 123, cond, 2.0), want, atol=1e-4)


@torch.no_grad()
def test_guidance_scale_0_is_the_unconditional_and_1_the_conditional_prediction() -> None:
    model, batch = _model(prediction="eps", x_scale=1.0), _batch()
    cond = model.condition(batch)
    x = torch.randn(3, 34, 126, generator=torch.Generator().manual_seed(3))
    t = torch.full((3,), 123)
    uncond = model.denoise(x, t, model.null_condition.expand_as(cond))
    conditional = model.denoise(x, t, cond)
    assert (uncond - conditional).abs().max() > 1e-3  # the null embedding is another input
    assert torch.allclose(model.guided_eps(x, 123, cond, 0.0), uncond, atol=1e-5)
    assert torch.allclose(model.guided_eps(x, 123, cond, 1.0), conditional, atol=1e-5)
    assert torch.allclose(model.guided_eps(x, 123, cond, 3.0), 3 * conditional - 2 * uncond, atol=1e-4)


def test_ddim_with_all_steps_and_eta_1_is_ddpm() -> None:
    """Song et al. 2021: eta = 1 and every step gives DDPM's reverse mean and variance (same noise draws)."""
    sched = NoiseSchedule(60, 1e-3, 0.05)
    w = torch.randn(126, 126, generator=torch.Generator().manual_seed(4), dtype=torch.float64) / 12

    def eps(x: torch.Tensor, t: int) -> torch.Tensor:  # any fixed function of (x, t)
        return torch.tanh(x @ w) + t / 60

    x_T = torch.randn(2, 34, 126, generator=torch.Generator().manual_seed(5), dtype=torch.float64)
    ddpm = ddpm_sample(sched, eps, x_T, generator=torch.Generator().manual_seed(6), stabilizer_t0=25)
    ddim = ddim_sample(sched, eps, x_T, steps=60, eta=1.0, generator=torch.Generator().manual_seed(6),
                       stabilizer_t0=25)  # fmt: skip
    assert torch.allclose(ddim, ddpm, rtol=1e-9, atol=1e-9)
    other = ddim_sample(sched, eps, x_T, steps=60, eta=0.0)
    assert (other - ddpm).abs().max() > 1e-2


def test_samples_depend_on_the_seed_only() -> None:
    model, batch = _model(), _batch()
    a = model.generate(batch, steps=5)
    assert torch.equal(a, model.generate(batch, steps=5))
    seeded = model.generate(batch, steps=5, generator=torch.Generator().manual_seed(3))
    assert torch.equal(seeded, model.generate(batch, steps=5, generator=torch.Generator().manual_seed(3)))
    assert (seeded - a).abs().max() > 1e-3
    ddpm = model.generate(batch, sampler="ddpm")
    assert torch.equal(ddpm, model.generate(batch, sampler="ddpm")) and torch.isfinite(ddpm).all()
    with pytest.raises(ValueError, match="DDPM takes all 500"):
        model.generate(batch, sampler="ddpm", steps=5)


@pytest.mark.parametrize(("b", "dropped"), [(2, 1), (10, 1), (128, 13)])
def test_the_condition_is_dropped_for_round_p_b_windows(b: int, dropped: int) -> None:
    model = _model()
    cond = torch.randn(b, 34, model.cond_dim)
    out = model.drop_condition(cond, torch.Generator().manual_seed(0))
    is_null = (out == model.null_condition).all(dim=-1).all(dim=-1)
    assert int(is_null.sum()) == dropped and torch.equal(out[~is_null], cond[~is_null])


def test_ddim_timesteps_and_the_schedule_ends() -> None:
    sched = NoiseSchedule(500, 1e-4, 0.02)
    assert sched.ddim_timesteps(500) == list(range(1, 501)) and sched.ddim_timesteps(1) == [500]
    assert sched.ddim_timesteps(50)[:2] == [10, 20] and sched.posterior_variance(1) == 0.0
    assert float(sched.alpha_bars[500]) == pytest.approx(_alpha_bars(500, 1e-4, 0.02)[500], rel=1e-12)


def test_paper_preset_sizes() -> None:
    """The reference's transformer: hidden 512, 4 + 4 blocks of 8 heads, MLP ratio 4; 500 steps, DDPM."""
    from beatlite.models import presets
    from beatlite.models.base import config_from_preset
    from beatlite.models.diffgesture import DiffGestureConfig

    c = config_from_preset(DiffGestureConfig, presets("diffgesture"), "paper")
    assert (c.hidden, c.depth, c.decoder_depth, c.heads, c.mlp_ratio) == (512, 4, 4, 8, 4.0)
    assert (c.diffusion_steps, c.beta_1, c.beta_T, c.null_cond_prob, c.guidance_scale) == (
        500,
        1e-4,
        0.02,
        0.1,
        1.15,
    )
    assert (c.sampler, c.stabilizer_t0) == ("ddpm", 25)


def test_a_long_take_is_generated_by_chaining_seeded_windows() -> None:
    """``train.generate_sequence`` (34-frame units every 30 frames, each seeded by the previous unit's last 4
    frames): a 100-frame take, finite, the same twice; another seed pose changes the take."""
    from beatlite.constants import FPS, SR
    from beatlite.train.generation import generate_sequence

    model = _model(sample_steps=2)
    rng = np.random.default_rng(0)
    streams = {
        "dirvec": (0.3 * rng.standard_normal((100, 126))).astype(np.float32),
        "audio": rng.uniform(-0.5, 0.5, int(100 / FPS * SR)).astype(np.float32),
    }
    out = generate_sequence(model, streams)
    assert out.shape == (100, 126) and np.isfinite(out).all()
    assert np.array_equal(out, generate_sequence(model, streams))
    other = dict(streams, dirvec=streams["dirvec"] + 0.5)
    assert np.abs(generate_sequence(model, other) - out).max() > 1e-3


def test_a_negative_eta_is_refused():
    """DDIM's eta is >= 0 (0 deterministic, 1 DDPM's variance); a negative one shrank the eps term and drew no
    noise, silently another sampler."""
    from beatlite.models.diffgesture import DiffGestureConfig, NoiseSchedule, ddim_sample

    with pytest.raises(ValueError, match="eta must be >= 0"):
        DiffGestureConfig(eta=-1.0)
    with pytest.raises(ValueError, match="eta must be >= 0"):
        ddim_sample(NoiseSchedule(10, 1e-4, 0.02), lambda x, t: x, torch.zeros(1, 4, 2), steps=5, eta=-1.0)
