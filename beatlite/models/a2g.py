"""A2G, Audio2Gestures (Li et al. 2021): the authors' conditional VAE with shared and motion-specific codes.

Li, Kang, Pei, Zhe, Zhang, He, Bao: "Audio2Gestures: generating diverse gestures from speech audio
with conditional variational autoencoders", ICCV 2021. It is the "A2G" row of BEAT Table 4 (BEAT
Sec. 6.3; Sec. 6.2 uses it as the VAE-based state of the art next to the GAN-based S2G); BEAT's
README names the authors' code (``JingLi513/Audio2Gestures``, ``model.py`` / ``module.py``, run by
its ``start.sh``) as the source of its A2G numbers. The ``paper`` preset has that code's layers,
widths, sampling and losses (docs/reference_code.md#a2g).

The idea: the latent code of a motion is split into a **shared code** ``z_s`` (what audio and
motion have in common: beats, rhythm) and a **motion-specific code** ``z_m`` (everything the audio
does not determine). An audio encoder predicts the shared code; a motion encoder gives both codes;
one decoder maps ``(z_s, z_m)`` back to motion. At inference the shared code comes from the audio
and the motion-specific code is *sampled*, so one audio clip has many gestures.

Data flow (T = 34 frames, per-frame codes; sizes of the ``paper`` preset, S = M = 16)::

    TCN(c_in, widths) = residual blocks [Conv1d(k3, dilation 2^i, same length) -> ReLU] x 2 (+ 1x1 skip)
    head(c, h, o)     = Linear(c, h) -> ReLU -> Linear(h, o)
    mel (B,70,128) -> mel/40 + 1 -> linear resampling to T frames -> TCN(128, 128 128 96 96 64)
                   -> head mu, head logvar (64 -> 32 -> S)                 -> z_a ~ N(mu, var) (B,T,S)
    pose (B,T,141) -> TCN(141, 256 256 128 128 64) -> Linear(64, 32) twice (shared / specific)
                   -> head mu, head logvar (32 -> 32 -> S or M) each    -> z_p (B,T,S), z_m (B,T,M) (sampled)
    mapping(z)     = Conv1d(M, M, k3) -> ReLU -> Conv1d -> ReLU -> Conv1d, heads mu/logvar (M -> M -> M), sampled
    decoder(z_s, z_m) = TCN(S + M, 64 128 128 256 256) -> Linear(256, 256) -> ReLU -> Linear(256, 141)

    "pose_motion" = decoder(z_p, z_m)        (reconstruction)
    "pose_cross"  = decoder(z_a, z_m)        (audio's shared code with the motion's specific code)
    "pose"        = decoder(z_a, z_x)        z_x = mapping(draw of N(mean_t z_m, sd_t z_m)) (training);
                                             inference: see ``eval_z``
    "z_x_share", "z_x_spec" = motion encoder codes of "pose" (the cycle terms)

Losses of :meth:`A2G.losses` (L1 means over elements unless said otherwise; the reference's
``start.sh`` weights):

- ``rec``, ``cross``: ``pose_motion`` and ``pose_cross`` vs the motion (``pose_weight`` 1 each);
- ``rec_speed``, ``cross_speed``: the same on frame differences ``x[t+1] - x[t]`` (``speed_weight`` 1);
- ``relaxed``: the relaxed motion loss of the sampled motion, the mean of ``|pose - motion|`` over the
  elements where it exceeds ``tolerance`` (``xpose_weight`` 1), and ``relaxed_speed``, the L1 of its
  frame differences (``xspeed_weight`` 5);
- ``code``: ``z_a`` vs ``z_p``, the shared-code constraint (``code_weight`` 0.1);
- ``cycle_spec``, ``cycle_share``: the motion encoder's codes of ``pose`` vs ``z_x`` and vs ``z_p``
  (``cycle_weight`` 0.1 each);
- ``diverse``: ``-L1(pose, pose_cross.detach())`` (``ds_weight`` 0.1, decayed linearly by
  ``ds_weight / ds_decay_steps`` per step, as in the reference);
- ``kl_audio``, ``kl_share``, ``kl_spec``, ``kl_mapping``: the KL divergence of each sampled code from
  N(0, I) as the reference sums it (over frames, then averaged over batch and channels), weighted by
  ``kl_weight`` (1e-3) times the reference's step schedule ``max((step // 10) % 10000 * 1e-4, 1e-4)``.

Inference (``eval_z``): ``"sample"`` (default, the reference) draws the audio's shared code from its
N(mu, var), picks one stored training clip's statistics of ``z_m`` (the reference picks one training
sequence's statistics, computed after training; beatlite keeps the last ``stat_pool`` training windows'
statistics in a buffer), draws ``z_x`` from them and passes it through the sampling mapping network.
Every draw comes from ``torch.Generator().manual_seed(seed + k)`` on the ``k``-th eval call since
construction or :meth:`A2G.reset`, so evaluations are reproducible. ``"mean"`` (an extra option, not
the paper's) uses every mean instead: the audio code's mu, the pool's average mean, the mapping's mu. On the
shipped ``a2g_tiny`` (seed 2021, ``data_samples/`` test split) sampling gives FGD 4.95, Diversity 20.6; the
means give FGD 18.5, Diversity 4.7 (one average code for every window is not a motion the decoder saw).

Differences from the reference code at the ``paper`` preset (same layers and parameter count):

- Audio: HA2G's 128-band log-mel (hop 512, 70 frames per 34-frame window, scaled ``mel / 40 + 1``)
  resampled linearly to the 34 pose frames, where the reference computes 64 bands at the pose frame
  rate and z-scores them with dataset statistics; so the audio TCN reads 128 channels (reference 64).
- Motion: the 141 z-scored Euler channels (``euler141``, like CaMN, S2G and Trimodal, so BEAT Table 4's
  rows share one representation), and the pose and speed losses are on those channels; the reference
  (Trinity) decodes 6-D rotations, adds a rotation-angle loss and measures positions and speeds after
  forward kinematics (``tolerance`` 0.02 is in its metres, here in z-scored units).
- 34-frame windows (the reference trains on 64), the recipe's optimiser settings (reference: Adam,
  lr 1e-4, batch 32), no seed pose and no speaker (as in the paper); the step counter of the KL and
  diversity schedules restarts with the model (it is a buffer, saved in checkpoints).
- The reference's KL sums over frames (its ``dim=1`` on a (B, T, C) code); kept.

Differences from the paper itself (Li et al. 2021, as far as its method section states them): the
reference code above is followed wherever the two differ.

The ``tiny`` preset (``a2g_tiny``, 40 epochs on ``data_samples/``) differs from ``paper`` in four ways:
every TCN and head is narrower (widths in :data:`PRESETS`); weights start from PyTorch's default
initialisation (``init_std=0``), not N(0, 0.01); the codes are their means (``vae=False``, the reference's
four ``--with_*_vae`` switches off, so no KL terms; inference still draws ``z_x`` from the stored code
statistics, so it still samples); and the three speed terms are off (``speed_weight`` = ``xspeed_weight`` = 0).
Measured on ``a2g_tiny``: with the reference's speed weights (1, 1, 5) the output froze into a static pose
(the sampled per-frame codes make any motion costly under the speed L1): seed 2021, train reconstruction L1
0.61 and validation FGD 23.4 after 10 epochs with either initialisation, next to the mean pose's 25.3 (in a
200-step fit of 64 training windows it stayed frozen with speed weights of 0.2 too). Without the speed terms but with sampled codes seed 2021 reached a best validation FGD of
4.6, while seed 2022 stayed frozen for 22 epochs and then diverged (non-finite poses: with the KL weight at
its schedule's 1e-7 nothing bounds the log-variances); with the means instead, seed 2022 reached 5.8 after
13 epochs. The reference trains for thousands of epochs at lr 1e-4.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import torch
from torch import nn

from beatlite.models.base import Batch, GestureModel, ModelConfig, check_batch
from beatlite.models.layers import reparameterize

POSE_DIM = 141
N_MELS = 128
EVAL_Z = ("sample", "mean")


@dataclasses.dataclass
class A2GConfig(ModelConfig):
    """A2G hyper-parameters (defaults = ``paper``: the authors' ``start.sh`` configuration).

    Attributes
    ----------
    audio_channels, motion_channels, decoder_channels : tuple of int
        Widths of the residual blocks of the audio encoder, motion encoder and decoder TCNs
        (reference ``[128, 128, 96, 96, 64]``, ``[256, 256, 128, 128, 64]``, ``[64, 128, 128, 256, 256]``).
    code_hidden : int
        Hidden width of the code heads and the motion encoder's two projections (reference 32).
    out_hidden : int
        Hidden width of the decoder's output MLP (reference 256).
    shared_dim, specific_dim : int
        Per-frame sizes S of the shared code and M of the motion-specific code (reference 16 + 16:
        ``audio_hidden_size``, ``pose_hidden_size``; the decoder reads ``hidden_size`` = S + M = 32).
    dropout : float
        Dropout in the residual blocks (reference 0).
    pose_weight, speed_weight, xpose_weight, xspeed_weight, code_weight, cycle_weight : float
        Loss weights (module docstring; ``start.sh``: 1, 1, 1, 5, 0.1, 0.1).
    ds_weight, ds_decay_steps : float, int
        Initial weight of the diversity term and the steps over which it decays to 0 (0.1, 500000).
    kl_weight : float
        ``lambda_kl`` of the four KL terms (1e-3), times the step schedule.
    tolerance : float
        Free distance of the relaxed motion loss, per element (0.02).
    init_std : float
        Standard deviation of the normal initialisation of every convolution and linear weight
        (biases 0), the reference's ``init``; 0 keeps PyTorch's default initialisation.
    vae : bool
        Sample the four codes (the reference's ``--with_audio_share_vae``, ``--with_motion_share_vae``,
        ``--with_motion_spec_vae``, ``--with_mapping_net_vae``, all on in its ``start.sh``); False uses
        their means (the ``z_x`` draw from the stored statistics stays) and freezes the log-variance heads.
    stat_pool : int
        Training windows whose ``z_m`` statistics are kept for inference.
    eval_z : str
        ``"sample"`` (default) or ``"mean"`` (module docstring).
    seed : int
        Base seed of the inference draws.
    """

    preset: str = "paper"
    audio_channels: tuple[int, ...] = (128, 128, 96, 96, 64)
    motion_channels: tuple[int, ...] = (256, 256, 128, 128, 64)
    decoder_channels: tuple[int, ...] = (64, 128, 128, 256, 256)
    code_hidden: int = 32
    out_hidden: int = 256
    shared_dim: int = 16
    specific_dim: int = 16
    dropout: float = 0.0
    pose_weight: float = 1.0
    speed_weight: float = 1.0
    xpose_weight: float = 1.0
    xspeed_weight: float = 5.0
    code_weight: float = 0.1
    cycle_weight: float = 0.1
    ds_weight: float = 0.1
    ds_decay_steps: int = 500_000
    kl_weight: float = 1e-3
    tolerance: float = 0.02
    init_std: float = 0.01
    vae: bool = True
    stat_pool: int = 512
    eval_z: str = "sample"
    seed: int = 0

    def __post_init__(self) -> None:
        for name in ("audio_channels", "motion_channels", "decoder_channels"):
            widths = tuple(int(c) for c in getattr(self, name))
            if not widths or min(widths) < 1:
                raise ValueError(f"A2GConfig: {name} must be positive widths, got {widths}")
            setattr(self, name, widths)
        if self.eval_z not in EVAL_Z:
            raise ValueError(f"A2GConfig: eval_z must be one of {EVAL_Z}, got {self.eval_z!r}")
        if self.stat_pool < 1:
            raise ValueError(f"A2GConfig: stat_pool must be >= 1, got {self.stat_pool}")


class ResidualBlock(nn.Module):
    """Two dilated ``Conv1d(k3) -> ReLU -> Dropout`` with a (1x1-projected) skip, then ReLU; length kept.

    Shapes: (B, c_in, T) -> (B, c_out, T). With ``padding = dilation`` each k3 convolution keeps the length;
    the receptive field of the block is ``4 * dilation + 1`` frames.

    Examples
    --------
    Four channels in, eight out over ten frames: the length is kept, and the final ReLU makes every value
    non-negative.

    >>> import torch
    >>> from beatlite.models.a2g import ResidualBlock
    >>> _ = torch.manual_seed(0)
    >>> y = ResidualBlock(4, 8, dilation=2, dropout=0.0)(torch.randn(1, 4, 10))
    >>> tuple(y.shape), bool((y >= 0).all())
    ((1, 8, 10), True)
    """

    def __init__(self, c_in: int, c_out: int, dilation: int, dropout: float) -> None:
        super().__init__()
        self.net = nn.Sequential(
            nn.Conv1d(c_in, c_out, 3, padding=dilation, dilation=dilation),
            nn.ReLU(),
            nn.Dropout(dropout),
            nn.Conv1d(c_out, c_out, 3, padding=dilation, dilation=dilation),
            nn.ReLU(),
            nn.Dropout(dropout),
        )
        self.skip = nn.Conv1d(c_in, c_out, 1) if c_in != c_out else nn.Identity()

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return torch.relu(self.net(x) + self.skip(x))


def tcn(c_in: int, widths: tuple[int, ...], dropout: float) -> nn.Sequential:
    """Residual blocks of ``widths`` with dilations 1, 2, 4, ...: (B, c_in, T) -> (B, widths[-1], T).

    Examples
    --------
    Three blocks: dilations 1, 2, 4, the last block's width out, the length kept.

    >>> import torch
    >>> from beatlite.models.a2g import tcn
    >>> net = tcn(5, (8, 8, 3), dropout=0.0)
    >>> [block.net[0].dilation[0] for block in net]
    [1, 2, 4]
    >>> tuple(net(torch.zeros(2, 5, 12)).shape)
    (2, 3, 12)
    """
    return nn.Sequential(
        *(ResidualBlock(c_in if i == 0 else widths[i - 1], w, 2**i, dropout) for i, w in enumerate(widths))
    )


def _head(c_in: int, hidden: int, c_out: int) -> nn.Sequential:
    return nn.Sequential(nn.Linear(c_in, hidden), nn.ReLU(), nn.Linear(hidden, c_out))


def kl_reference(mu: torch.Tensor, logvar: torch.Tensor) -> torch.Tensor:
    """The reference's KL of a (B, T, C) code: summed over frames T, averaged over B and C.

    ``= T * layers.kl_standard_normal(mu, logvar)``.

    Parameters
    ----------
    mu, logvar : (B, T, C) float tensors
        A per-frame code's means and log-variances.

    Returns
    -------
    () float tensor, nats (per window and channel).

    Examples
    --------
    Every element N(1, 1) (0.5 nat each) over T = 4 frames: ``4 * 0.5 = 2``.

    >>> import torch
    >>> from beatlite.models.a2g import kl_reference
    >>> float(kl_reference(torch.ones(3, 4, 2), torch.zeros(3, 4, 2)))
    2.0
    """
    return torch.mean(-0.5 * torch.sum(1 + logvar - mu.pow(2) - logvar.exp(), dim=1))


def kl_schedule(step: int | torch.Tensor) -> float | torch.Tensor:
    """The reference's KL weight factor at training step ``step``: ``max((step // 10) % 10000 * 1e-4, 1e-4)``.

    It rises from 1e-4 to 0.9999 over 100000 steps, then starts again. ``step`` may be an integer
    tensor (the model's step counter, on the training device): the factor is then a float64 tensor
    there, with the same value, so that the losses never read the counter back to the host.

    Examples
    --------
    >>> kl_schedule(0), kl_schedule(25), kl_schedule(100_000)
    (0.0001, 0.0002, 0.0001)
    """
    if torch.is_tensor(step):
        return (((step // 10) % 10000).double() * 1e-4).clamp(min=1e-4)
    return max((int(step) // 10) % 10000 * 1e-4, 1e-4)


def _weighted(weight: float | torch.Tensor, loss: torch.Tensor) -> torch.Tensor:
    """``weight * loss`` in ``loss``'s dtype, with a float64 weight tensor (a scheduled weight kept on the
    device) multiplied as a Python float would be: in float32 (torch's arithmetic type for float32 and
    bfloat16), then rounded to ``loss``'s dtype."""
    if not torch.is_tensor(weight):
        return weight * loss
    return (weight.float() * loss.float()).to(loss.dtype)


def speed(x: torch.Tensor) -> torch.Tensor:
    """Frame differences ``x[:, 1:] - x[:, :-1]``: (B, T, D) -> (B, T - 1, D), units of ``x`` per frame.

    Examples
    --------
    >>> import torch
    >>> from beatlite.models.a2g import speed
    >>> speed(torch.tensor([0.0, 1.0, 3.0, 6.0]).reshape(1, 4, 1)).flatten()
    tensor([1., 2., 3.])
    """
    return x[:, 1:] - x[:, :-1]


class _Gaussian(nn.Module):
    """Two heads (mean, log-variance) over the last axis: (..., c_in) -> mu, logvar (..., c_out)."""

    def __init__(self, c_in: int, hidden: int, c_out: int) -> None:
        super().__init__()
        self.mean = _head(c_in, hidden, c_out)
        self.logvar = _head(c_in, hidden, c_out)

    def forward(self, x: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        return self.mean(x), self.logvar(x)


class A2G(GestureModel):
    """Audio-only conditional VAE with shared and motion-specific codes (module docstring).

    Shapes: ``batch["mel"]`` (B, M, 128) dB, ``batch["pose"]`` (B, T, 141) (read by the motion
    encoder; :meth:`generate` zeroes it after the seed, which ``"pose"`` never reads) ->
    ``{"pose", "pose_motion", "pose_cross"}`` (B, T, 141), ``"z_audio"``, ``"z_pose"``, ``"z_x_share"``
    (B, T, S), ``"z_m"``, ``"z_x"``, ``"z_x_spec"`` (B, T, M), and the (mu, logvar) pairs
    ``"audio_mu"``/``"audio_logvar"``, ``"share_mu"``/..., ``"spec_mu"``/..., ``"map_mu"``/... .
    In training mode also ``"z_x_share"`` (B, T, S) and ``"z_x_spec"`` (B, T, M), the cycle codes.

    Parameters
    ----------
    config : A2GConfig
        Build one with ``beatlite.models.build_model("a2g", preset="tiny")``.

    Examples
    --------
    A tiny A2G on two fake 34-frame windows (70 mel frames): every decoding has the pose's shape and each code
    S = M = 16 channels per frame; ``tiny`` uses the codes' means (``vae=False``), so the audio's shared code is
    its mean and the KL terms weigh nothing.

    >>> import torch
    >>> from beatlite.models import build_model
    >>> from beatlite.models.testing import fake_batch
    >>> _ = torch.manual_seed(0)
    >>> model = build_model("a2g", preset="tiny")
    >>> batch = fake_batch(2)
    >>> out = model({"pose": batch["pose"], "mel": batch["mel"]})
    >>> tuple(out["pose"].shape), tuple(out["pose_cross"].shape), tuple(out["z_audio"].shape), tuple(out["z_m"].shape)
    ((2, 34, 141), (2, 34, 141), (2, 34, 16), (2, 34, 16))
    >>> torch.equal(out["z_audio"], out["audio_mu"])
    True
    >>> losses = model.losses(batch, out, epoch=0)
    >>> int(model.steps), bool(torch.isfinite(losses["total"]))  # a training-mode call counts a step
    (1, True)

    Inference samples the motion-specific code, reproducibly: :meth:`reset` restarts the draws.

    >>> model.reset()
    >>> first = model.generate(batch)
    >>> model.reset()
    >>> torch.equal(model.generate(batch), first), tuple(first.shape)
    (True, (2, 34, 141))
    """

    name = "a2g"
    representation = "euler141"
    config_class = A2GConfig
    input_keys = ("pose", "mel")

    def __init__(self, config: A2GConfig) -> None:
        super().__init__(config)
        cfg = config
        s, m, h = cfg.shared_dim, cfg.specific_dim, cfg.code_hidden
        self.audio_encoder = tcn(N_MELS, cfg.audio_channels, cfg.dropout)
        self.audio_code = _Gaussian(cfg.audio_channels[-1], h, s)
        self.motion_encoder = tcn(POSE_DIM, cfg.motion_channels, cfg.dropout)
        self.share_linear = nn.Linear(cfg.motion_channels[-1], h)
        self.spec_linear = nn.Linear(cfg.motion_channels[-1], h)
        self.share_code = _Gaussian(h, h, s)
        self.spec_code = _Gaussian(h, h, m)
        self.decoder = tcn(s + m, cfg.decoder_channels, cfg.dropout)
        self.pose_out = _head(cfg.decoder_channels[-1], cfg.out_hidden, POSE_DIM)
        self.mapping = nn.Sequential(
            nn.Conv1d(m, m, 3, padding=1), nn.ReLU(),
            nn.Conv1d(m, m, 3, padding=1), nn.ReLU(),
            nn.Conv1d(m, m, 3, padding=1),
        )  # fmt: skip
        self.mapping_code = _Gaussian(m, m, m)
        if not cfg.vae:  # the log-variance heads exist (as in the reference) but are never used
            for gaussian in (self.audio_code, self.share_code, self.spec_code, self.mapping_code):
                gaussian.logvar.requires_grad_(False)
        for module in self.modules() if cfg.init_std > 0 else ():  # the reference's init
            if isinstance(module, (nn.Conv1d, nn.Linear)):
                nn.init.normal_(module.weight, 0.0, cfg.init_std)
                nn.init.zeros_(module.bias)
        self.register_buffer("steps", torch.zeros((), dtype=torch.long))
        self.register_buffer("spec_stats", torch.zeros(cfg.stat_pool, 2, m))
        self.register_buffer("n_stats", torch.zeros((), dtype=torch.long))
        self._calls = 0

    def reset(self) -> None:
        """Restart the sequence of inference draws."""
        self._calls = 0

    # ------------------------------------------------------------------ parts
    def encode_audio(self, mel: torch.Tensor, t: int) -> tuple[torch.Tensor, torch.Tensor]:
        """(B, M, 128) dB -> mu, logvar (B, t, S) of the shared code."""
        if mel.ndim != 3 or mel.shape[2] != N_MELS or mel.shape[1] < 1:
            raise ValueError(f"A2G: batch['mel'] must be (B, M >= 1, {N_MELS}), got shape {tuple(mel.shape)}")
        x = (mel / 40.0 + 1.0).transpose(1, 2)
        x = nn.functional.interpolate(x, size=t, mode="linear", align_corners=True)
        return self.audio_code(self.audio_encoder(x).transpose(1, 2))

    def encode_motion(self, pose: torch.Tensor) -> tuple[torch.Tensor, ...]:
        """(B, T, 141) -> shared mu, logvar (B, T, S), specific mu, logvar (B, T, M)."""
        h = self.motion_encoder(pose.transpose(1, 2)).transpose(1, 2)
        return (*self.share_code(self.share_linear(h)), *self.spec_code(self.spec_linear(h)))

    def decode(self, shared: torch.Tensor, specific: torch.Tensor) -> torch.Tensor:
        """(B, T, S), (B, T, M) -> (B, T, 141)."""
        h = self.decoder(torch.cat([shared, specific], -1).transpose(1, 2)).transpose(1, 2)
        return self.pose_out(h)

    def map_code(self, z: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """The mapping network: (B, T, M) -> mu, logvar (B, T, M)."""
        return self.mapping_code(self.mapping(z.transpose(1, 2)).transpose(1, 2))

    # ------------------------------------------------------------------ sampling
    def _noise(self, like: torch.Tensor, gen: torch.Generator | None) -> torch.Tensor:
        if gen is None:
            return torch.randn_like(like)
        return torch.randn(like.shape, generator=gen, dtype=torch.float32).to(like)

    @torch.no_grad()
    def _store_stats(self, z_m: torch.Tensor) -> None:
        """Append each window's (mean, sd over frames) of ``z_m`` to the ring buffer ``spec_stats``."""
        stats = torch.stack([z_m.mean(1), z_m.std(1)], 1).float()[-self.config.stat_pool :]
        k, pool = stats.shape[0], self.config.stat_pool
        idx = (self.n_stats + torch.arange(k, device=stats.device)) % pool  # on the device: no host read
        self.spec_stats[idx] = stats
        self.n_stats += k

    def _eval_specific(self, shape: torch.Size, gen: torch.Generator, like: torch.Tensor) -> torch.Tensor:
        """Inference ``z_x`` before the mapping network (B, T, M): drawn from one stored clip's statistics."""
        b, t, m = shape
        n = min(int(self.n_stats), self.config.stat_pool)
        if n == 0:  # never trained: the prior
            mean, sd = torch.zeros(b, m), torch.ones(b, m)
        elif self.config.eval_z == "mean":
            mean, sd = self.spec_stats[:n, 0].mean(0).expand(b, m), torch.zeros(b, m)
        else:
            pick = torch.randint(0, n, (b,), generator=gen)
            mean, sd = self.spec_stats[pick, 0], self.spec_stats[pick, 1]
        noise = torch.randn((b, t, m), generator=gen)
        return (mean.unsqueeze(1) + sd.unsqueeze(1) * noise).to(like)

    # ------------------------------------------------------------------ forward
    def forward(self, batch: Batch) -> dict[str, torch.Tensor]:
        """The three decodings, the codes and their Gaussians (class docstring)."""
        check_batch(batch, self.input_keys, "A2G")
        pose = batch["pose"]
        if pose.ndim != 3 or pose.shape[-1] != POSE_DIM:
            raise ValueError(f"A2G: batch['pose'] must be (B, T, {POSE_DIM}), got shape {tuple(pose.shape)}")
        t = pose.shape[1]
        gen = None
        mean_only = (not self.training and self.config.eval_z == "mean") or not self.config.vae
        if not self.training:
            gen = torch.Generator().manual_seed(int(self.config.seed) + self._calls)
            self._calls += 1
        audio_mu, audio_logvar = self.encode_audio(batch["mel"], t)
        share_mu, share_logvar, spec_mu, spec_logvar = self.encode_motion(pose)
        if mean_only:
            z_audio, z_pose, z_m = audio_mu, share_mu, spec_mu
        else:
            z_audio = reparameterize(audio_mu, audio_logvar, self._noise(audio_mu, gen))
            z_pose = reparameterize(share_mu, share_logvar, self._noise(share_mu, gen))
            z_m = reparameterize(spec_mu, spec_logvar, self._noise(spec_mu, gen))
        if self.training:
            self._store_stats(z_m.detach())
            scale = z_m.std(1, keepdim=True).detach()  # the reference samples without gradient
            z_in = z_m.mean(1, keepdim=True).detach() + scale * torch.randn_like(z_m)
        else:
            z_in = self._eval_specific(z_m.shape, gen, z_m)
        map_mu, map_logvar = self.map_code(z_in)
        z_x = map_mu if mean_only else reparameterize(map_mu, map_logvar, self._noise(map_mu, gen))
        gen_pose = self.decode(z_audio, z_x)
        out = {
            "pose": gen_pose,
            "pose_motion": self.decode(z_pose, z_m),
            "pose_cross": self.decode(z_audio, z_m),
            "z_audio": z_audio,
            "z_pose": z_pose,
            "z_m": z_m,
            "z_x": z_x,
            "audio_mu": audio_mu,
            "audio_logvar": audio_logvar,
            "share_mu": share_mu,
            "share_logvar": share_logvar,
            "spec_mu": spec_mu,
            "spec_logvar": spec_logvar,
            "map_mu": map_mu,
            "map_logvar": map_logvar,
        }
        if self.training:  # the cycle codes: the motion encoder's (sampled) codes of the sampled motion
            c_share_mu, c_share_logvar, c_spec_mu, c_spec_logvar = self.encode_motion(gen_pose)
            out["z_x_share"] = reparameterize(c_share_mu, c_share_logvar, torch.randn_like(c_share_mu))
            out["z_x_spec"] = reparameterize(c_spec_mu, c_spec_logvar, torch.randn_like(c_spec_mu))
        return out

    def losses(self, batch: Batch, out: dict[str, torch.Tensor], *, epoch: int) -> dict[str, torch.Tensor]:
        """The reference's loss terms and ``"total"`` (module docstring); a training-mode call counts a step."""
        cfg = self.config
        target = batch["pose"]
        l1 = nn.functional.l1_loss
        step = self.steps  # on the device: the scheduled weights are tensors there (no host read per step)
        distance = (out["pose"] - target).abs()
        over = distance > cfg.tolerance
        relaxed = (distance * over).sum() / over.sum().clamp(min=1)  # mean beyond the tolerance (0 if none)
        parts = {
            "rec": l1(out["pose_motion"], target),
            "cross": l1(out["pose_cross"], target),
            "rec_speed": l1(speed(out["pose_motion"]), speed(target)),
            "cross_speed": l1(speed(out["pose_cross"]), speed(target)),
            "relaxed": relaxed,
            "relaxed_speed": l1(speed(out["pose"]), speed(target)),
            "code": l1(out["z_audio"], out["z_pose"]),
            "kl_audio": kl_reference(out["audio_mu"], out["audio_logvar"]),
            "kl_share": kl_reference(out["share_mu"], out["share_logvar"]),
            "kl_spec": kl_reference(out["spec_mu"], out["spec_logvar"]),
            "kl_mapping": kl_reference(out["map_mu"], out["map_logvar"]),
            "diverse": -l1(out["pose"], out["pose_cross"].detach()),
        }
        weights = {
            "rec": cfg.pose_weight,
            "cross": cfg.pose_weight,
            "rec_speed": cfg.speed_weight,
            "cross_speed": cfg.speed_weight,
            "relaxed": cfg.xpose_weight,
            "relaxed_speed": cfg.xspeed_weight,
            "code": cfg.code_weight,
            "diverse": (cfg.ds_weight * (1.0 - step.double() / cfg.ds_decay_steps)).clamp(min=0.0)
            if cfg.ds_decay_steps
            else 0.0,
            **dict.fromkeys(
                ("kl_audio", "kl_share", "kl_spec", "kl_mapping"), cfg.kl_weight * kl_schedule(step) * cfg.vae
            ),
        }
        if "z_x_spec" in out:
            parts["cycle_spec"] = l1(out["z_x_spec"], out["z_x"])
            parts["cycle_share"] = l1(out["z_x_share"], out["z_pose"])
            weights["cycle_spec"] = weights["cycle_share"] = cfg.cycle_weight
        parts["total"] = sum(_weighted(w, parts[k]) for k, w in weights.items())
        if self.training:
            self.steps += 1
        return parts


PRESETS: dict[str, dict[str, Any]] = {
    "paper": {},
    "tiny": {
        "audio_channels": (32, 32, 24, 24, 16),
        "motion_channels": (64, 64, 32, 32, 16),
        "decoder_channels": (16, 32, 32, 64, 64),
        "code_hidden": 16,
        "out_hidden": 64,
        "stat_pool": 256,
        "init_std": 0.0,
        "vae": False,
        "speed_weight": 0.0,
        "xspeed_weight": 0.0,
    },
}
"""``paper``: the reference's widths and losses (2.47 M parameters); ``tiny``: every TCN and head a quarter to
half as wide (0.21 M), same code sizes (16 + 16), PyTorch's default initialisation, codes = their means and no
speed terms (module docstring: the reference's sampling and speed terms froze or broke the 40-epoch recipe)."""
