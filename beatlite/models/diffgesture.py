"""DiffGesture-style diffusion model on TED direction vectors (dirvec126): :class:`DiffGesture`.

Zhu, Liu, Liu, Qian, Liu and Yu, "Taming Diffusion Models for Audio-Driven Co-Speech Gesture Generation",
CVPR 2023 (DiffGesture); code: https://github.com/Advocate99/DiffGesture (``scripts/model/pose_diffusion.py``,
``diffusion_net.py``, ``diffusion_util.py``, ``config/pose_diffusion_expressive.yml``; what it does, its evaluation
included: docs/reference_code.md#diffgesture). Read for the design, written anew here.

What it keeps from the paper and its code
-----------------------------------------
- **Representation**: TED Expressive bone directions, 34-frame windows, 4 seed frames (HA2G's protocol), i.e.
  beatlite's ``dirvec126``.
- **Forward process** (DDPM, Ho et al. 2020): ``q(x_t | x_0) = N(sqrt(abar_t) x_0, (1 - abar_t) I)`` with a linear
  schedule ``beta_1 = 1e-4 .. beta_T = 0.02`` over ``T = 500`` steps (:class:`NoiseSchedule`).
- **Objective**: epsilon prediction, as the reference (``get_loss`` regresses the added noise): ``loss =
  mean((eps_theta(x_t, t, c) - eps)^2)`` with ``t`` uniform in ``1..T``.
- **Condition** ``c`` per frame: the seed poses with their indicator bit (:func:`~beatlite.models.base.seed_input`,
  127 channels) and audio features of the raw waveform from the reference's 4-convolution encoder
  (:class:`~beatlite.models.layers.PlainWavEncoder`, 32 channels per frame). The "Diffusion Audio-Gesture
  Transformer" concatenates ``x_t``, the step code and ``c`` per frame, projects to ``hidden``, adds a learned
  position embedding and runs two stacks of pre-norm self-attention blocks (the code's ``depth`` and
  ``decoder_depth``, each closed by a LayerNorm), then ``Linear(h, h/2) -> LeakyReLU -> Linear(h/2, 126)``.
- **Implicit classifier-free guidance** (Ho & Salimans 2021): in training the condition of a window is replaced by a
  learned null embedding with probability ``null_cond_prob`` (0.1); sampling uses ``eps_u + s (eps_c - eps_u)``
  with ``s = guidance_scale`` (the code's 1.15).
- **Diffusion Gesture Stabilizer** (annealed noise sampling): for the last steps ``1 < t < t0`` (``t0 = 25`` in the
  code) the sampling noise of the frames shares a component: ``z_n = a e + sqrt(1 - a^2) e_n`` with ``a = ((t -
  t0) / t0)^2``, one ``e`` per window and ``e_n`` per frame (each frame's noise stays N(0, I)).
- **Sampling**: DDPM ancestral sampling with the posterior variance ``beta~_t`` (the code's ``flexibility = 0``),
  and DDIM (Song et al. 2021) on ``steps`` evenly spaced steps with ``eta`` (0: deterministic given ``x_T``).

What differs
------------
- The step code: the reference concatenates ``(beta_t, sin beta_t, cos beta_t)`` per frame; ``beta_t`` spans only
  1e-4..0.02, so the network sees an almost constant input. Here it is a sinusoidal code of ``t`` (``time_dim``
  channels, Vaswani et al. 2017), concatenated the same way.
- The head's LeakyReLU: the reference passes ``True`` as its slope (a slope of 1, i.e. a linear head); here 0.2.
- Initialisation: PyTorch's defaults and a position embedding drawn from N(0, 0.02^2); the reference initialises
  every linear layer Xavier-uniform with zero biases and its position embedding from N(0, 1).
- Condition dropping: with a batch of B >= 2 windows exactly ``clamp(round(p B), 1, B - 1)`` windows lose their
  condition (chosen at random), so the null embedding and the condition path both get a gradient in every step
  (the :class:`~beatlite.models.base.GestureModel` contract; DistributedDataParallel needs it); at B = 128 that is
  13 windows (10.2 %, p = 0.1). A batch of one window drops with probability p.
- ``generate`` is seeded (``config.seed``, a ``torch.Generator``): one batch gives the same samples every call.
- The ``tiny`` preset predicts the clean window (``prediction="x0"``, as MDM, Tevet et al. ICLR 2023) of the
  directions scaled by 3 (``x_scale``: mean-subtracted directions have a standard deviation of about 0.3, the
  schedule assumes about 1), trains in minutes on a CPU and samples with DDIM in 25 steps. With the paper's
  epsilon-prediction on unscaled directions, the same budget (40 epochs of ``data_samples/``) sampled far from the
  data: test FGD 2174 (DDIM 50 steps) against 7.2 with these two changes; the noise estimate's error at large
  ``t`` is amplified ``1 / sqrt(abar_t)`` (up to 12 times) in the clean-window estimate. The ``paper`` preset keeps
  epsilon-prediction on unscaled directions.

Outputs of :meth:`DiffGesture.forward` (the training pass: one noise level per window): ``"pose"`` the clean
window predicted (B, T, 126), ``"eps"`` the noise estimate, ``"noise"`` the noise added, ``"t"`` the steps (B,)
int64, ``"x0"`` the clean window in diffused units (``x_scale`` times ``batch["dirvec"]``). :meth:`DiffGesture.generate` samples (the whole reverse process).

Taught in ``notebooks/10_diffusion.ipynb``.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from typing import Any

import torch
from torch import nn

from beatlite.constants import WINDOW_LENGTH
from beatlite.models.base import Batch, GestureModel, ModelConfig, check_batch, evaluating, seed_input
from beatlite.models.layers import PlainWavEncoder, match_length

POSE_DIM = 126
SAMPLERS = ("ddpm", "ddim")
PREDICTIONS = ("eps", "x0")

PRESETS: dict[str, dict[str, Any]] = {
    # hidden / 2 >= 126: the noise estimate passes through the head's hidden / 2 channels (the noise MSE stalled
    # at every step t: 0.76 at hidden 64, 0.26 at hidden 192, near the rank deficit 30 / 126 of a 96-wide head)
    # x0-prediction on 3 x the directions: with the paper's eps-prediction on the directions as they are, 40 epochs
    # on data_samples sampled far from the data (test FGD 2174 with DDIM 50); these two changes gave 7.2 at 40 epochs
    # and 4.4 at 60 when chosen (DDIM 25 steps, seed 2021; recipes.DIFFGESTURE_EPOCHS; today's seeds:
    # checkpoints/results_seeds.md)
    "tiny": {"hidden": 256, "depth": 1, "decoder_depth": 1, "heads": 4, "mlp_ratio": 2.0, "sampler": "ddim",
             "sample_steps": 25, "prediction": "x0", "x_scale": 3.0},
    # config/pose_diffusion_expressive.yml and pose_diffusion.py: hidden 512, block_depth 8 (4 + 4), 8 heads,
    # MLP ratio 4, 500 steps, beta 1e-4..0.02, null_cond_prob 0.1, guidance 1.15, DDPM with the stabilizer
    "paper": {"hidden": 512, "depth": 4, "decoder_depth": 4, "heads": 8, "mlp_ratio": 4.0, "sampler": "ddpm",
              "sample_steps": 500, "prediction": "eps", "x_scale": 1.0},
}  # fmt: skip
"""Preset -> config overrides."""


@dataclasses.dataclass
class DiffGestureConfig(ModelConfig):
    """DiffGesture hyper-parameters (defaults = ``tiny``).

    Attributes
    ----------
    hidden, heads : int
        Width of the transformer and its attention heads (``hidden % heads == 0``); the noise estimate of the
        126 channels passes through the head's ``hidden // 2`` channels, so ``hidden`` should be at least 252.
    depth, decoder_depth : int
        Self-attention blocks of the two stacks (the reference's ``block_depth // 2`` each).
    mlp_ratio : float
        Feed-forward width / ``hidden``.
    time_dim : int
        Channels of the sinusoidal step code (even).
    audio_channels : 4 ints
        Widths of the waveform encoder; ``audio_channels[-1]`` features per frame.
    diffusion_steps : int
        T, steps of the forward process.
    beta_1, beta_T : float
        Ends of the linear variance schedule.
    null_cond_prob : float
        Probability of dropping the condition in training (0: no guidance, no null embedding).
    guidance_scale : float
        Default guidance scale ``s`` of :meth:`DiffGesture.generate` (0: unconditional, 1: conditional).
    sampler : "ddpm" or "ddim"
        Default sampler of :meth:`DiffGesture.generate`.
    sample_steps : int
        Default DDIM steps (1..T; DDPM always takes T).
    eta : float
        DDIM's noise scale (0: deterministic; 1 with ``sample_steps == T``: DDPM).
    stabilizer_t0 : int
        The stabilizer's last noisy steps ``t0`` (0 or 1: off).
    prediction : "eps" or "x0"
        What the network predicts: the noise (the paper's) or the clean window (as MDM, Tevet et al. ICLR 2023);
        the loss is the mean squared error of that prediction; samplers get the noise it implies.
    x_scale : float
        The windows are diffused as ``x_scale * dirvec`` (1: the paper's); mean-subtracted directions have a
        standard deviation of about 0.3, so 3 gives the schedule the unit-variance data it is designed for.
    clip_x0 : float or None
        In sampling, the clean-window estimate of every step is clipped to ``[-clip_x0, clip_x0]`` (in diffused
        units) before the next step is taken (None: off, the paper's).
    seed : int
        Seed of the sampling generator of :meth:`DiffGesture.generate` and of eval-mode forward passes.
    n_frames : int
        Frames T per window (the position embedding is sized for it).
    """

    hidden: int = 256
    depth: int = 1
    decoder_depth: int = 1
    heads: int = 4
    mlp_ratio: float = 2.0
    time_dim: int = 16
    audio_channels: tuple[int, ...] = (16, 32, 64, 32)
    diffusion_steps: int = 500
    beta_1: float = 1e-4
    beta_T: float = 0.02
    null_cond_prob: float = 0.1
    guidance_scale: float = 1.15
    sampler: str = "ddim"
    sample_steps: int = 25
    eta: float = 0.0
    stabilizer_t0: int = 25
    prediction: str = "x0"
    x_scale: float = 3.0
    clip_x0: float | None = None
    seed: int = 0
    n_frames: int = WINDOW_LENGTH

    def __post_init__(self) -> None:
        self.audio_channels = tuple(int(c) for c in self.audio_channels)
        if self.sampler not in SAMPLERS:
            raise ValueError(f"sampler must be one of {SAMPLERS}, got {self.sampler!r}")
        if self.prediction not in PREDICTIONS:
            raise ValueError(f"prediction must be one of {PREDICTIONS}, got {self.prediction!r}")
        if not self.x_scale > 0 or (self.clip_x0 is not None and not self.clip_x0 > 0):
            raise ValueError(f"x_scale and clip_x0 must be positive, got {self.x_scale}, {self.clip_x0}")
        if self.hidden % self.heads or self.time_dim % 2:
            raise ValueError(f"hidden ({self.hidden}) must divide by heads ({self.heads}), time_dim be even")
        if not 0.0 <= self.null_cond_prob < 1.0:
            raise ValueError(f"null_cond_prob must be in [0, 1), got {self.null_cond_prob}")
        if not self.eta >= 0.0:
            raise ValueError(f"eta must be >= 0 (0: deterministic DDIM, 1: DDPM's variance), got {self.eta}")
        if not 1 <= self.sample_steps <= self.diffusion_steps:
            raise ValueError(f"sample_steps must be in [1, {self.diffusion_steps}], got {self.sample_steps}")


# ---------------------------------------------------------------------------- the diffusion process
class NoiseSchedule:
    """The DDPM forward process of a linear variance schedule, in float64 (steps are 1-based).

    Parameters
    ----------
    steps : int
        T.
    beta_1, beta_T : float
        ``betas = linspace(beta_1, beta_T, T)``.

    Attributes
    ----------
    betas, alphas, alpha_bars : (T + 1,) float64 tensors
        Index ``t`` is step ``t``; index 0 is the clean data (``beta_0 = 0``, ``abar_0 = 1``);
        ``abar_t = prod_{s <= t} (1 - beta_s)``.

    Examples
    --------
    Two steps with betas 0.1 and 0.5: ``abar = 1, 0.9, 0.9 * 0.5 = 0.45``, and DDPM's reverse variance at step 2
    is ``(1 - 0.9) / (1 - 0.45) * 0.5 = 0.0909``.

    >>> import torch
    >>> from beatlite.models.diffgesture import NoiseSchedule
    >>> schedule = NoiseSchedule(2, 0.1, 0.5)
    >>> schedule.alpha_bars.tolist()
    [1.0, 0.9, 0.45]
    >>> round(schedule.posterior_variance(2), 4)
    0.0909

    :meth:`predict_x0` undoes :meth:`q_sample` given the noise, and DDIM's steps are evenly spaced:

    >>> _ = torch.manual_seed(0)
    >>> x0, noise, t = torch.randn(3, 4, 5), torch.randn(3, 4, 5), torch.tensor([0, 1, 2])
    >>> x_t = schedule.q_sample(x0, t, noise)
    >>> bool(torch.allclose(schedule.predict_x0(x_t, t, noise), x0, atol=1e-6))
    True
    >>> NoiseSchedule(500, 1e-4, 0.02).ddim_timesteps(5)
    [100, 200, 300, 400, 500]
    """

    def __init__(self, steps: int, beta_1: float, beta_T: float) -> None:
        if steps < 1 or not 0.0 < beta_1 <= beta_T < 1.0:
            raise ValueError(f"need steps >= 1 and 0 < beta_1 <= beta_T < 1, got {steps}, {beta_1}, {beta_T}")
        self.steps = int(steps)
        zero = torch.zeros(1, dtype=torch.float64)
        self.betas = torch.cat([zero, torch.linspace(beta_1, beta_T, steps, dtype=torch.float64)])
        self.alphas = 1.0 - self.betas
        self.alpha_bars = torch.cumprod(self.alphas, 0)
        self._on_device: dict[torch.device, dict[str, torch.Tensor]] = {}

    def _at(self, name: str, t: torch.Tensor, like: torch.Tensor) -> torch.Tensor:
        """Table ``name`` at the steps ``t``, as (B, 1, 1) in ``like``'s dtype and device.

        Indexed on ``like``'s device (where the model draws ``t``), from a copy of the table made there once:
        no host copy of ``t`` per call (which would make the host wait for the device at every training step).
        """
        device = like.device
        tables = self._on_device.get(device)
        if tables is None:
            names = ("betas", "alphas", "alpha_bars")
            tables = self._on_device[device] = {n: getattr(self, n).to(device) for n in names}
        return tables[name][t.to(device)].to(like.dtype).view(-1, *([1] * (like.ndim - 1)))

    def q_sample(self, x0: torch.Tensor, t: torch.Tensor, noise: torch.Tensor) -> torch.Tensor:
        """A draw of ``x_t ~ q(x_t | x_0)`` in closed form: ``sqrt(abar_t) x0 + sqrt(1 - abar_t) noise``.

        Parameters
        ----------
        x0, noise : (B, ...) float tensors
        t : (B,) int64 tensor, steps in 0..T
        """
        ab = self._at("alpha_bars", t, x0)
        return ab.sqrt() * x0 + (1.0 - ab).sqrt() * noise

    def q_step(self, x_prev: torch.Tensor, t: torch.Tensor, noise: torch.Tensor) -> torch.Tensor:
        """One step of the forward kernel ``q(x_t | x_{t-1}) = N(sqrt(alpha_t) x_{t-1}, beta_t I)``."""
        return self._at("alphas", t, x_prev).sqrt() * x_prev + self._at("betas", t, x_prev).sqrt() * noise

    def predict_x0(self, x_t: torch.Tensor, t: torch.Tensor, eps: torch.Tensor) -> torch.Tensor:
        """The clean window implied by a noise estimate: ``(x_t - sqrt(1 - abar_t) eps) / sqrt(abar_t)``."""
        ab = self._at("alpha_bars", t, x_t)
        return (x_t - (1.0 - ab).sqrt() * eps) / ab.sqrt()

    def predict_eps(self, x_t: torch.Tensor, t: torch.Tensor, x0: torch.Tensor) -> torch.Tensor:
        """The noise implied by a clean-window estimate: ``(x_t - sqrt(abar_t) x0) / sqrt(1 - abar_t)``."""
        ab = self._at("alpha_bars", t, x_t)
        return (x_t - ab.sqrt() * x0) / (1.0 - ab).sqrt()

    def posterior_variance(self, t: int) -> float:
        """``beta~_t = (1 - abar_{t-1}) / (1 - abar_t) beta_t`` (0 at t = 1), DDPM's reverse variance."""
        ab = self.alpha_bars
        return float((1.0 - ab[t - 1]) / (1.0 - ab[t]) * self.betas[t])

    def ddim_timesteps(self, steps: int) -> list[int]:
        """``steps`` increasing steps ``round(i T / steps)``, i = 1..steps (all of 1..T when steps = T)."""
        if not 1 <= steps <= self.steps:
            raise ValueError(f"steps must be in [1, {self.steps}], got {steps}")
        return [round(i * self.steps / steps) for i in range(1, steps + 1)]


EpsFn = Callable[[torch.Tensor, int], torch.Tensor]
"""A noise estimate ``eps(x_t, t)``: (B, T, D) tensor and the step (1..T) -> (B, T, D)."""


def sampling_noise(
    shape: tuple[int, ...], t: int, t0: int, generator: torch.Generator | None, like: torch.Tensor
) -> torch.Tensor:
    """The reverse step's N(0, I) noise, with the stabilizer's shared component for ``1 < t < t0``.

    Returns
    -------
    (B, T, D) tensor
        ``randn`` for ``t >= t0``; else ``a e + sqrt(1 - a^2) e_n`` with ``a = ((t - t0) / t0)^2``, one
        ``e`` (B, 1, D) per window and ``e_n`` per frame (drawn in that order).

    Examples
    --------
    At step 2 of ``t0 = 25``, ``a = (23 / 25)^2 = 0.846``: two frames of a window share ``a^2 = 0.716`` of their
    unit variance (correlation over 20000 channels, one decimal); from ``t0`` on the frames are independent.

    >>> import torch
    >>> from beatlite.models.diffgesture import sampling_noise
    >>> like = torch.zeros(())
    >>> z = sampling_noise((1, 2, 20000), 2, 25, torch.Generator().manual_seed(0), like)
    >>> round(float(torch.corrcoef(z[0])[0, 1]), 1), round(float(z.std()), 1)
    (0.7, 1.0)
    >>> z = sampling_noise((1, 2, 20000), 25, 25, torch.Generator().manual_seed(0), like)
    >>> round(float(torch.corrcoef(z[0])[0, 1]), 1)
    0.0
    """
    kw = {"generator": generator, "device": like.device, "dtype": like.dtype}
    if not 1 < t < t0:
        return torch.randn(shape, **kw)
    a = ((t - t0) / t0) ** 2
    shared = torch.randn((shape[0], 1, *shape[2:]), **kw)
    return a * shared + math.sqrt(1.0 - a * a) * torch.randn(shape, **kw)


def ddpm_sample(
    schedule: NoiseSchedule, eps_fn: EpsFn, x_T: torch.Tensor, *,
    generator: torch.Generator | None = None, stabilizer_t0: int = 0,
) -> torch.Tensor:  # fmt: skip
    """DDPM ancestral sampling from ``x_T`` over all T steps (reverse variance ``beta~_t``).

    ``x_{t-1} = (x_t - beta_t / sqrt(1 - abar_t) eps) / sqrt(alpha_t) + sqrt(beta~_t) z`` with ``z`` from
    :func:`sampling_noise` (drawn for t > 1 only).

    Parameters
    ----------
    schedule : NoiseSchedule
    eps_fn : callable
        ``eps_fn(x_t, t)``: the noise estimate (B, T, D) at step ``t`` (1..T).
    x_T : (B, T, D) float tensor
        The start, a draw of N(0, I).
    generator : torch.Generator, optional
        Source of the sampling noise.
    stabilizer_t0 : int
        :func:`sampling_noise`'s ``t0`` (0: off).

    Returns
    -------
    (B, T, D) tensor, x_0

    Examples
    --------
    With an oracle that knows the clean window (the noise it implies at every step), the last step lands on it
    whatever noise was added on the way (at step 1, ``abar_1 = alpha_1``, the update is :meth:`NoiseSchedule.predict_x0`):

    >>> import torch
    >>> from beatlite.models.diffgesture import NoiseSchedule, ddpm_sample
    >>> schedule = NoiseSchedule(10, 1e-3, 0.2)
    >>> _ = torch.manual_seed(0)
    >>> x0 = torch.randn(2, 4, 3, dtype=torch.float64)
    >>> def oracle(x, t):
    ...     return schedule.predict_eps(x, torch.full((x.shape[0],), t), x0)
    >>> x = ddpm_sample(schedule, oracle, torch.randn_like(x0), generator=torch.Generator().manual_seed(1))
    >>> bool(torch.allclose(x, x0))
    True
    """
    x = x_T
    for t in range(schedule.steps, 0, -1):
        eps = eps_fn(x, t)
        alpha, ab = float(schedule.alphas[t]), float(schedule.alpha_bars[t])
        x = (x - (1.0 - alpha) / math.sqrt(1.0 - ab) * eps) / math.sqrt(alpha)
        if t > 1:
            z = sampling_noise(tuple(x.shape), t, stabilizer_t0, generator, x)
            x = x + math.sqrt(schedule.posterior_variance(t)) * z
    return x


def ddim_sample(
    schedule: NoiseSchedule, eps_fn: EpsFn, x_T: torch.Tensor, *, steps: int, eta: float = 0.0,
    generator: torch.Generator | None = None, stabilizer_t0: int = 0,
) -> torch.Tensor:  # fmt: skip
    """DDIM sampling on :meth:`NoiseSchedule.ddim_timesteps` (``steps`` network calls).

    From step ``t`` to the previous one ``p`` (0 after the first): ``x0 = predict_x0(x_t, eps)``,
    ``x_p = sqrt(abar_p) x0 + sqrt(1 - abar_p - sigma^2) eps + sigma z`` with
    ``sigma = eta sqrt((1 - abar_p) / (1 - abar_t)) sqrt(1 - abar_t / abar_p)`` (noise drawn when sigma > 0).

    Parameters
    ----------
    schedule : NoiseSchedule
    eps_fn : callable
        ``eps_fn(x_t, t)``: the noise estimate (B, T, D) at step ``t`` (1..T).
    x_T : (B, T, D) float tensor
        The start, a draw of N(0, I).
    steps : int
        Network calls, 1..T.
    eta : float
        Noise scale (0: deterministic; 1 with ``steps == T``: DDPM's variance).
    generator : torch.Generator, optional
        Source of the sampling noise (``eta > 0``).
    stabilizer_t0 : int
        :func:`sampling_noise`'s ``t0`` (0: off).

    Returns
    -------
    (B, T, D) tensor, x_0

    Examples
    --------
    With an oracle noise estimate (the noise implied by a known clean window) two deterministic DDIM steps
    (``t`` = 5, 10 of 10) recover the clean window from any start:

    >>> import torch
    >>> from beatlite.models.diffgesture import NoiseSchedule, ddim_sample
    >>> schedule = NoiseSchedule(10, 1e-3, 0.2)
    >>> _ = torch.manual_seed(0)
    >>> x0 = torch.randn(2, 4, 3, dtype=torch.float64)
    >>> def oracle(x, t):
    ...     return schedule.predict_eps(x, torch.full((x.shape[0],), t), x0)
    >>> bool(torch.allclose(ddim_sample(schedule, oracle, torch.randn_like(x0), steps=2), x0))
    True
    """
    if not eta >= 0.0:  # (a negative eta would shrink the eps term and draw no noise: another sampler)
        raise ValueError(f"eta must be >= 0 (0: deterministic DDIM, 1: DDPM's variance), got {eta}")
    times = schedule.ddim_timesteps(steps)
    x = x_T
    for i in range(len(times) - 1, -1, -1):
        t, p = times[i], (times[i - 1] if i > 0 else 0)
        eps = eps_fn(x, t)
        ab_t, ab_p = float(schedule.alpha_bars[t]), float(schedule.alpha_bars[p])
        x0 = (x - math.sqrt(1.0 - ab_t) * eps) / math.sqrt(ab_t)
        sigma = eta * math.sqrt((1.0 - ab_p) / (1.0 - ab_t) * (1.0 - ab_t / ab_p))
        x = math.sqrt(ab_p) * x0 + math.sqrt(max(0.0, 1.0 - ab_p - sigma * sigma)) * eps
        if sigma > 0.0:
            x = x + sigma * sampling_noise(tuple(x.shape), t, stabilizer_t0, generator, x)
    return x


def step_code(t: torch.Tensor, dim: int, steps: int) -> torch.Tensor:
    """Sinusoidal code of the steps ``t`` (B,) -> (B, dim): ``sin`` / ``cos`` of ``t`` at ``dim / 2`` frequencies
    from 1 to ``1 / steps`` (geometric; radians per step).

    Examples
    --------
    Four channels for 100 steps: frequencies 1 and 1/100; step 0 is ``(0, 0, 1, 1)``, step 1 is
    ``(sin 1, sin 0.01, cos 1, cos 0.01)``.

    >>> import torch
    >>> from beatlite.models.diffgesture import step_code
    >>> step_code(torch.tensor([0, 1]), 4, 100).numpy().round(4)
    array([[0.    , 0.    , 1.    , 1.    ],
           [0.8415, 0.01  , 0.5403, 1.    ]], dtype=float32)
    """
    half = dim // 2
    freqs = torch.exp(-math.log(max(steps, 2)) * torch.arange(half, device=t.device) / max(half - 1, 1))
    angle = t.to(torch.float32)[:, None] * freqs[None]
    return torch.cat([torch.sin(angle), torch.cos(angle)], dim=-1)


# ---------------------------------------------------------------------------- the network
class DiffGesture(GestureModel):
    """DiffGesture-style conditional diffusion on 34-frame dirvec126 windows (see the module docstring).

    Parameters
    ----------
    config : DiffGestureConfig
        Build one with ``beatlite.models.build_model("diffgesture", preset="tiny")``.

    Examples
    --------
    The training pass of a tiny model on a fake window: one step per window, the clean window diffused as
    ``x_scale = 3`` times the directions, and (``prediction="x0"``) the loss is the clean-window estimate's mean
    squared error in diffused units.

    >>> import torch
    >>> from beatlite.models import build_model
    >>> from beatlite.models.testing import fake_batch
    >>> _ = torch.manual_seed(0)
    >>> model = build_model("diffgesture", preset="tiny")
    >>> batch = fake_batch(1)
    >>> batch = {"dirvec": batch["dirvec"], "audio": batch["audio"]}
    >>> out = model(batch)
    >>> tuple(out["pose"].shape), tuple(out["t"].shape), torch.equal(out["x0"], 3 * batch["dirvec"])
    ((1, 34, 126), (1,), True)
    >>> loss = model.losses(batch, out, epoch=0)["total"]
    >>> bool(torch.isclose(loss, ((3 * out["pose"] - out["x0"]) ** 2).mean()))
    True

    Sampling (here DDIM in 2 steps) is seeded by ``config.seed``: the same batch gives the same window.

    >>> first = model.generate(batch, steps=2)
    >>> tuple(first.shape), torch.equal(model.generate(batch, steps=2), first)
    ((1, 34, 126), True)
    """

    name = "diffgesture"
    representation = "dirvec126"
    config_class = DiffGestureConfig
    input_keys = ("dirvec", "audio")

    def __init__(self, config: DiffGestureConfig) -> None:
        super().__init__(config)
        c = config
        self.schedule = NoiseSchedule(c.diffusion_steps, c.beta_1, c.beta_T)
        self.audio_encoder = PlainWavEncoder(c.audio_channels)
        self.cond_dim = POSE_DIM + 1 + c.audio_channels[-1]
        self.null_condition = nn.Parameter(torch.randn(self.cond_dim)) if c.null_cond_prob > 0 else None
        self.input = nn.Linear(POSE_DIM + c.time_dim + self.cond_dim, c.hidden)
        self.position = nn.Parameter(0.02 * torch.randn(1, c.n_frames, c.hidden))
        self.encoder = self._stack(c.depth)
        self.decoder = self._stack(c.decoder_depth)
        self.encoder_norm, self.decoder_norm = nn.LayerNorm(c.hidden), nn.LayerNorm(c.hidden)
        self.head = nn.Sequential(
            nn.Linear(c.hidden, c.hidden // 2), nn.LeakyReLU(0.2), nn.Linear(c.hidden // 2, POSE_DIM)
        )

    def _stack(self, depth: int) -> nn.ModuleList:
        """``depth`` pre-norm self-attention blocks (GELU MLP, no dropout: timm's ``Block`` of the code)."""
        c = self.config
        return nn.ModuleList(
            nn.TransformerEncoderLayer(
                c.hidden,
                c.heads,
                int(c.hidden * c.mlp_ratio),
                dropout=0.0,
                activation="gelu",
                batch_first=True,
                norm_first=True,
            )  # fmt: skip
            for _ in range(depth)
        )

    # ------------------------------------------------------------------ pieces
    def condition(self, batch: Batch) -> torch.Tensor:
        """The per-frame condition ``[seed_input(dirvec) (127), audio features (A)]`` -> (B, T, 127 + A)."""
        check_batch(batch, self.input_keys, "DiffGesture")
        pose = batch["dirvec"]
        if pose.ndim != 3 or pose.shape[1:] != (self.config.n_frames, POSE_DIM):
            raise ValueError(
                f"DiffGesture: batch['dirvec'] must be (B, {self.config.n_frames}, {POSE_DIM}), "
                f"got {tuple(pose.shape)}"
            )
        audio = match_length(self.audio_encoder(batch["audio"]), pose.shape[1])
        return torch.cat([seed_input(pose, self.n_pre), audio.to(pose.dtype)], dim=-1)

    def denoise(self, x_t: torch.Tensor, t: torch.Tensor, cond: torch.Tensor) -> torch.Tensor:
        """The noise estimate ``eps_theta(x_t, t, c)``.

        Parameters
        ----------
        x_t : (B, T, 126) float tensor
        t : (B,) int64 tensor, steps 1..T
        cond : (B, T, C) float tensor, the condition (or the null embedding, broadcast)

        Returns
        -------
        (B, T, 126) float tensor
        """
        code = step_code(t, self.config.time_dim, self.schedule.steps).to(x_t.dtype)
        code = code[:, None].expand(-1, x_t.shape[1], -1)
        h = self.input(torch.cat([x_t, code, cond.to(x_t.dtype)], dim=-1)) + self.position
        for block in self.encoder:
            h = block(h)
        h = self.encoder_norm(h)
        for block in self.decoder:
            h = block(h)
        return self.head(self.decoder_norm(h))

    def drop_condition(self, cond: torch.Tensor, generator: torch.Generator | None = None) -> torch.Tensor:
        """Replace the condition of ``clamp(round(p B), 1, B - 1)`` random windows by the null embedding
        (B >= 2; one window: with probability p); unchanged without a null embedding."""
        if self.null_condition is None:
            return cond
        b, p = cond.shape[0], self.config.null_cond_prob
        if b == 1:
            drop = torch.rand(1, generator=generator, device=cond.device) < p
        else:
            k = min(max(round(p * b), 1), b - 1)
            order = torch.randperm(b, generator=generator, device=cond.device)
            drop = torch.zeros(b, dtype=torch.bool, device=cond.device)
            drop[order[:k]] = True
        return torch.where(drop[:, None, None], self.null_condition.to(cond.dtype), cond)

    def guided_eps(self, x_t: torch.Tensor, t: int, cond: torch.Tensor, scale: float) -> torch.Tensor:
        """``eps_u + scale (eps_c - eps_u)`` in one batched pass (without a null embedding: ``eps_c``).

        With ``prediction="x0"`` the two clean-window estimates are combined the same way (the noise is affine in
        it) and converted; with ``clip_x0`` the clean-window estimate is clipped before that.

        Parameters
        ----------
        x_t : (B, T, 126) tensor
        t : int, the step (1..T)
        cond : (B, T, C) tensor
        scale : float, the guidance scale s
        """
        steps = torch.full((x_t.shape[0],), t, dtype=torch.int64, device=x_t.device)
        if self.null_condition is None:
            out = self.denoise(x_t, steps, cond)
        else:
            null = self.null_condition.to(cond.dtype).expand_as(cond)
            out_u, out_c = self.denoise(
                torch.cat([x_t, x_t]), torch.cat([steps, steps]), torch.cat([null, cond])
            ).chunk(2)
            out = out_u + scale * (out_c - out_u)
        c = self.config
        if c.prediction == "eps" and c.clip_x0 is None:
            return out
        x0 = out if c.prediction == "x0" else self.schedule.predict_x0(x_t, steps, out)
        if c.clip_x0 is not None:
            x0 = x0.clamp(-c.clip_x0, c.clip_x0)
        return self.schedule.predict_eps(x_t, steps, x0)

    def _generator(self, device: torch.device, seed: int | None = None) -> torch.Generator:
        return torch.Generator(device=device).manual_seed(self.config.seed if seed is None else int(seed))

    # ------------------------------------------------------------------ contract
    def forward(self, batch: Batch) -> dict[str, torch.Tensor]:
        """The training pass: ``{"pose": x0 estimate, "eps", "noise", "t", "x0"}`` (see the module docstring).

        Training mode draws ``t``, the noise and the dropped windows from torch's global generator; eval mode
        from one seeded with ``config.seed`` (validation losses are the same at every epoch's end).
        """
        cond = self.condition(batch)
        x0 = batch["dirvec"] * self.config.x_scale
        g = None if self.training else self._generator(x0.device)
        t = torch.randint(1, self.schedule.steps + 1, (x0.shape[0],), generator=g, device=x0.device)
        noise = torch.randn(x0.shape, generator=g, device=x0.device, dtype=x0.dtype)
        if self.training:
            cond = self.drop_condition(cond, g)
        x_t = self.schedule.q_sample(x0, t, noise)
        out = self.denoise(x_t, t, cond).to(x_t.dtype)
        if self.config.prediction == "x0":
            x0_hat, eps = out, self.schedule.predict_eps(x_t, t, out)
        else:
            x0_hat, eps = self.schedule.predict_x0(x_t, t, out), out
        return {"pose": x0_hat / self.config.x_scale, "eps": eps, "noise": noise, "t": t, "x0": x0}

    def losses(self, batch: Batch, out: dict[str, torch.Tensor], *, epoch: int) -> dict[str, torch.Tensor]:
        """``{"eps": mean squared error of the noise estimate, "total": the same}``; with ``prediction="x0"``,
        ``{"x0": mean squared error of the clean-window estimate (diffused units), "total": the same}``."""
        if self.config.prediction == "x0":
            x0 = nn.functional.mse_loss(out["pose"].float() * self.config.x_scale, out["x0"].float())
            return {"x0": x0, "total": x0}
        eps = nn.functional.mse_loss(out["eps"].float(), out["noise"].float())
        return {"eps": eps, "total": eps}

    @torch.no_grad()
    def generate(
        self, batch: Batch, *, sampler: str | None = None, steps: int | None = None,
        guidance_scale: float | None = None, eta: float | None = None, generator: torch.Generator | None = None,
    ) -> torch.Tensor:  # fmt: skip
        """Sample windows seeded by the first ``n_pre`` frames of ``batch["dirvec"]`` and the audio.

        Parameters
        ----------
        batch : dict of tensors
            ``"dirvec"`` (B, T, 126) (frames ``>= n_pre`` are zeroed first) and ``"audio"`` (B, S).
        sampler : "ddpm" or "ddim", optional
            Default ``config.sampler``.
        steps : int, optional
            DDIM steps (default ``config.sample_steps``); DDPM takes all T (giving another value raises).
        guidance_scale, eta : float, optional
            Defaults ``config.guidance_scale``, ``config.eta`` (DDIM only).
        generator : torch.Generator, optional
            Source of ``x_T`` and the sampling noise (on the model's device); default one seeded with
            ``config.seed``, so the same batch gives the same samples.

        Returns
        -------
        (B, T, 126) float tensor, normalised directions
        """
        c = self.config
        sampler = c.sampler if sampler is None else sampler
        if sampler not in SAMPLERS:
            raise ValueError(f"sampler must be one of {SAMPLERS}, got {sampler!r}")
        if sampler == "ddpm" and steps not in (None, self.schedule.steps):
            raise ValueError(f"DDPM takes all {self.schedule.steps} steps; use sampler='ddim' for {steps}")
        scale = c.guidance_scale if guidance_scale is None else float(guidance_scale)
        check_batch(batch, self.input_keys, "DiffGesture.generate")
        with evaluating(self):
            seeded = dict(batch)
            seeded["dirvec"] = batch["dirvec"].clone()
            seeded["dirvec"][:, self.n_pre :] = 0.0
            cond = self.condition(seeded)
            g = generator if generator is not None else self._generator(cond.device)
            x_T = torch.randn(seeded["dirvec"].shape, generator=g, device=cond.device, dtype=cond.dtype)

            def eps_fn(x: torch.Tensor, t: int) -> torch.Tensor:
                return self.guided_eps(x, t, cond, scale).to(x.dtype)

            if sampler == "ddpm":
                x0 = ddpm_sample(self.schedule, eps_fn, x_T, generator=g, stabilizer_t0=c.stabilizer_t0)
            else:
                x0 = ddim_sample(
                    self.schedule, eps_fn, x_T, steps=c.sample_steps if steps is None else int(steps),
                    eta=c.eta if eta is None else float(eta), generator=g, stabilizer_t0=c.stabilizer_t0,
                )  # fmt: skip
            return x0 / c.x_scale
