"""A2G, Audio2Gestures (Li et al. 2021) as a compact conditional VAE, runnable on a CPU.

Li, Kang, Pei, Zhe, Zhang, He, Bao: "Audio2Gestures: generating diverse gestures from speech audio
with conditional variational autoencoders", ICCV 2021 (method section; its abstract names the parts
below). It is the "A2G" row of BEAT Table 4 (BEAT Sec. 6.3; Sec. 6.2 uses it as the VAE-based state of
the art next to the GAN-based S2G).

The idea kept: the latent code of a motion is split into a **shared code** ``z_s`` (what audio and
motion have in common: beats, rhythm) and a **motion-specific code** ``z_m`` (everything the audio
does not determine). An audio encoder predicts the shared code; a motion encoder gives both codes;
one decoder maps ``(z_s, z_m)`` back to motion. At inference the shared code comes from the audio
and the motion-specific code from the prior N(0, I), so one audio clip has many gestures.

Data flow (T = 34 frames, per-frame codes; sizes of the ``paper`` preset)::

    convs(c_in, c_out) = Conv1d(k3, hidden) -> LReLU -> Conv1d(k3, hidden) -> LReLU -> Conv1d(k1, c_out)
    audio (B,36266) -> PlainWavEncoder (Trimodal's 4 convs, 34 frames of 32) -> convs(32, S)   -> z_a (B,T,S)
    pose (B,T,141)  -> convs(141, S + 2M) -> z_p (B,T,S), mu (B,T,M), logvar (B,T,M)
    decoder(z_s, z_m) = convs(S + M, 141) on cat[z_s, z_m]                             -> (B,T,141)

    "pose"        = decoder(z_a, eps)      eps ~ N(0, I) (training); see ``eval_z`` (inference)
    "pose_motion" = decoder(z_p, z_m)      z_m = mu + exp(logvar / 2) * N(0, I) (eval: mu)
    "pose_cross"  = decoder(z_a, z_m)

Losses of :meth:`A2G.losses` (all L1 means unless said otherwise), kept from the paper:

- ``rec``: ``pose_motion`` vs the motion (the VAE's reconstruction);
- ``cross``: ``pose_cross`` vs the motion (the audio's shared code must stand in for the motion's);
- ``shared``: ``z_a`` vs ``z_p`` (the shared-code constraint);
- ``kld``: ``-0.5 mean(1 + logvar - mu^2 - exp(logvar))``, the closed-form KL divergence of
  N(mu, exp(logvar)) from N(0, 1) per element;
- ``relaxed``: the relaxed motion loss ``mean_b max(0, mean_{t,d} |pose - motion| - margin)``:
  a motion drawn with a random ``eps`` may differ from the ground truth by ``relaxed_margin``
  (z-scored units) at no cost;
- ``bicycle``: the bicycle constraint, ``mu`` of the motion encoder on ``pose`` vs ``eps``
  (the random code must be recoverable from the motion it produced, so the decoder cannot ignore it).

Simplified or left out: the mapping network that maps noise to motion-specific codes (here ``eps``
is drawn from N(0, I) directly), the diversity loss, the paper's backbone and audio features
(here small 1-D convolutions and the raw-waveform encoder of :class:`~beatlite.models.layers.PlainWavEncoder`),
and its 64-frame clips (34 here). The output is ``euler141`` like CaMN, S2G and Trimodal, so BEAT
Table 4's rows share one representation. No seed pose and no speaker, as in the paper.

Inference (``eval_z``): ``"mean"`` (default) decodes the prior mean ``eps = 0`` (deterministic,
like Trimodal's ``z = mu``); ``"sample"`` draws ``eps`` from ``torch.Generator().manual_seed(seed + k)``
on the ``k``-th eval call since construction or :meth:`A2G.reset` (reproducible diversity).
"""

from __future__ import annotations

import dataclasses
from typing import Any

import torch
from torch import nn

from beatlite.models.base import Batch, GestureModel, ModelConfig, check_batch
from beatlite.models.layers import PlainWavEncoder, match_length

POSE_DIM = 141
EVAL_Z = ("mean", "sample")


@dataclasses.dataclass
class A2GConfig(ModelConfig):
    """A2G hyper-parameters (defaults = the ``paper`` preset).

    Attributes
    ----------
    audio_channels : tuple of 4 int
        :class:`~beatlite.models.layers.PlainWavEncoder` widths.
    hidden : int
        Channels of the motion encoder, audio head and decoder convolutions.
    shared_dim, specific_dim : int
        Per-frame sizes S of the shared code and M of the motion-specific code.
    slope : float
        LeakyReLU slope.
    rec_weight, cross_weight, shared_weight, kld_weight, relaxed_weight, bicycle_weight : float
        Weights of the loss terms (module docstring). ``kld_weight`` 1 (``a2g_tiny``, seed 2021): at
        0.01 the motion-specific code drifted from the prior (KL 1.9 per element, 0.1 at weight 1), so
        the N(0, I) codes of inference were codes the decoder had not seen; the best validation FGD of
        40 epochs was the same within noise (12.7 at 0.01, 13.0 at 1; 16.5 vs 22.3 after 12 epochs).
    relaxed_margin : float
        Free L1 distance (z-scored units) of the relaxed motion loss. 0.2 (``a2g_tiny``, seed 2021):
        best validation FGD of 40 epochs 7.9, against 13.0 at 0.5, where the sampled motions, the
        ones inference produces, were hardly trained (the mean pose is 0.8 from a motion).
    eval_z : str
        ``"mean"`` or ``"sample"`` (module docstring).
    seed : int
        Base seed of ``eval_z="sample"``.
    """

    preset: str = "paper"
    audio_channels: tuple[int, ...] = (16, 32, 64, 32)
    hidden: int = 256
    shared_dim: int = 32
    specific_dim: int = 32
    slope: float = 0.2
    rec_weight: float = 1.0
    cross_weight: float = 1.0
    shared_weight: float = 1.0
    kld_weight: float = 1.0
    relaxed_weight: float = 1.0
    relaxed_margin: float = 0.2
    bicycle_weight: float = 1.0
    eval_z: str = "mean"
    seed: int = 0

    def __post_init__(self) -> None:
        self.audio_channels = tuple(int(c) for c in self.audio_channels)
        if self.eval_z not in EVAL_Z:
            raise ValueError(f"A2GConfig: eval_z must be one of {EVAL_Z}, got {self.eval_z!r}")


def _convs(c_in: int, hidden: int, c_out: int, slope: float) -> nn.Sequential:
    """``Conv1d(k3) -> LReLU -> Conv1d(k3) -> LReLU -> Conv1d(k1)``: (B, c_in, T) -> (B, c_out, T)."""
    return nn.Sequential(
        nn.Conv1d(c_in, hidden, 3, padding=1),
        nn.LeakyReLU(slope),
        nn.Conv1d(hidden, hidden, 3, padding=1),
        nn.LeakyReLU(slope),
        nn.Conv1d(hidden, c_out, 1),
    )


def kl_standard_normal(mu: torch.Tensor, logvar: torch.Tensor) -> torch.Tensor:
    """Mean over elements of KL(N(mu, exp(logvar)) || N(0, 1)) = ``-0.5 (1 + logvar - mu^2 - exp(logvar))``."""
    return -0.5 * torch.mean(1 + logvar - mu.pow(2) - logvar.exp())


def reparameterize(mu: torch.Tensor, logvar: torch.Tensor, noise: torch.Tensor) -> torch.Tensor:
    """``mu + exp(logvar / 2) * noise``: a draw of N(mu, exp(logvar)) that is differentiable in mu, logvar."""
    return mu + torch.exp(0.5 * logvar) * noise


class A2G(GestureModel):
    """Audio-only conditional VAE with shared and motion-specific codes (module docstring).

    Shapes: ``batch["audio"]`` (B, S) float, ``batch["pose"]`` (B, T, 141) (read by the motion
    encoder; :meth:`generate` zeroes it after the seed, which ``"pose"`` never reads) ->
    ``{"pose", "pose_motion", "pose_cross"}`` (B, T, 141), ``"z_audio"``, ``"z_pose"`` (B, T, S),
    ``"mu"``, ``"logvar"``, ``"eps"``, ``"eps_rec"`` (B, T, M).
    """

    name = "a2g"
    representation = "euler141"
    config_class = A2GConfig
    input_keys = ("pose", "audio")

    def __init__(self, config: A2GConfig) -> None:
        super().__init__(config)
        cfg = config
        s, m = cfg.shared_dim, cfg.specific_dim
        self.audio_encoder = PlainWavEncoder(cfg.audio_channels)
        self.audio_head = _convs(cfg.audio_channels[-1], cfg.hidden, s, cfg.slope)
        self.motion_encoder = _convs(POSE_DIM, cfg.hidden, s + 2 * m, cfg.slope)
        self.decoder = _convs(s + m, cfg.hidden, POSE_DIM, cfg.slope)
        self._calls = 0

    def reset(self) -> None:
        """Restart the sequence of ``eval_z="sample"`` draws."""
        self._calls = 0

    def encode_motion(self, pose: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """(B, T, 141) -> shared code (B, T, S), mu and logvar (B, T, M) of the motion-specific code."""
        h = self.motion_encoder(pose.transpose(1, 2)).transpose(1, 2)
        s, m = self.config.shared_dim, self.config.specific_dim
        return h[..., :s], h[..., s : s + m], h[..., s + m :]

    def decode(self, shared: torch.Tensor, specific: torch.Tensor) -> torch.Tensor:
        """(B, T, S), (B, T, M) -> (B, T, 141)."""
        return self.decoder(torch.cat([shared, specific], -1).transpose(1, 2)).transpose(1, 2)

    def _eps(self, like: torch.Tensor) -> torch.Tensor:
        if self.training:
            return torch.randn_like(like)
        if self.config.eval_z == "mean":
            return torch.zeros_like(like)
        gen = torch.Generator().manual_seed(int(self.config.seed) + self._calls)
        self._calls += 1
        return torch.randn(like.shape, generator=gen).to(like)

    def forward(self, batch: Batch) -> dict[str, torch.Tensor]:
        """The three decodings and the codes (class docstring)."""
        check_batch(batch, self.input_keys, "A2G")
        pose = batch["pose"]
        if pose.ndim != 3 or pose.shape[-1] != POSE_DIM:
            raise ValueError(f"A2G: batch['pose'] must be (B, T, {POSE_DIM}), got shape {tuple(pose.shape)}")
        t = pose.shape[1]
        wav = match_length(self.audio_encoder(batch["audio"]), t)
        z_audio = self.audio_head(wav.transpose(1, 2)).transpose(1, 2)
        z_pose, mu, logvar = self.encode_motion(pose)
        z_m = reparameterize(mu, logvar, torch.randn_like(mu)) if self.training else mu
        eps = self._eps(mu)
        gen = self.decode(z_audio, eps)
        return {
            "pose": gen,
            "pose_motion": self.decode(z_pose, z_m),
            "pose_cross": self.decode(z_audio, z_m),
            "z_audio": z_audio,
            "z_pose": z_pose,
            "mu": mu,
            "logvar": logvar,
            "eps": eps,
            "eps_rec": self.encode_motion(gen)[1],
        }

    def losses(self, batch: Batch, out: dict[str, torch.Tensor], *, epoch: int) -> dict[str, torch.Tensor]:
        """``{"rec", "cross", "shared", "kld", "relaxed", "bicycle", "total"}`` (module docstring)."""
        cfg = self.config
        target = batch["pose"]
        l1 = nn.functional.l1_loss
        parts = {
            "rec": l1(out["pose_motion"], target),
            "cross": l1(out["pose_cross"], target),
            "shared": l1(out["z_audio"], out["z_pose"]),
            "kld": kl_standard_normal(out["mu"], out["logvar"]),
            "relaxed": torch.relu((out["pose"] - target).abs().mean(dim=(1, 2)) - cfg.relaxed_margin).mean(),
            "bicycle": l1(out["eps_rec"], out["eps"]),
        }
        weights = {
            "rec": cfg.rec_weight,
            "cross": cfg.cross_weight,
            "shared": cfg.shared_weight,
            "kld": cfg.kld_weight,
            "relaxed": cfg.relaxed_weight,
            "bicycle": cfg.bicycle_weight,
        }
        parts["total"] = sum(weights[k] * parts[k] for k in weights)
        return parts


PRESETS: dict[str, dict[str, Any]] = {
    "paper": {},
    "tiny": {"hidden": 48, "shared_dim": 16, "specific_dim": 16},
}
"""``paper``: 256-wide convolutions, 32 + 32 code channels per frame; ``tiny``: 48 wide, 16 + 16."""
