"""HA2G: Hierarchical Audio-to-Gesture (Liu et al., CVPR 2022), a CPU-sized re-implementation (torch).

The model predicts 34-frame windows of TED-43 bone directions (``windows["dirvec"]``,
(B, 34, 126): 42 unit vectors minus their training mean) from

- a log-mel spectrogram (``"mel"`` (B, 70, 128)) through the hierarchical audio learner
  (:mod:`beatlite.models.ha2g_audio`: low / mid / high features per frame),
- word ids (``"word"`` (B, 34)) through a TCN text encoder,
- a speaker id (``"speaker"`` (B,)) through a reparameterised style vector z (mu, logvar),
- the first ``n_pre = 4`` frames of ``"dirvec"`` (the seed poses).

The speaker's style drives two things (paper Sec. 3.3): a style coordinator that turns it into
softmax weights over the three audio levels for each body level (paper eq. 3), and the pose
generators. Two designs, chosen by ``HA2GConfig.style``:

- ``"reference"`` (the ``tiny`` and ``paper`` presets; HA2G's code): the coordinator has its own
  speaker embedding (``Embedding -> Linear``), and every level generator its own reparameterised
  style code ``z_k`` (``Embedding -> Linear -> (mu_k, logvar_k)``). The KL term and the style
  diverging loss read the last level's code; the style loss compares each sample with the
  output for another speaker of the batch (a permutation of the batch's speakers; same
  coordinator weights), per-sample z distances, the other output detached.
- ``"shared"`` (the design of checkpoints trained before the field existed, which lack it):
  one reparameterised z (``Embedding -> Linear -> LeakyReLU -> (mu, logvar)``) drives the
  coordinator and all generators; the style loss divides by the batch-mean z distance, uses
  uniformly random speaker ids and back-propagates through both outputs.

The pose inferer runs one bidirectional GRU per body level
(``beatlite.skeleton.ted.HA2G_LEVELS``: spine/shoulders/head -> upper arms -> forearms ->
three rings of finger phalanges, 24/30/36/66/96/126 channels); level k's seed input
carries level k-1's prediction in the channels they share (HA2G §3.3, eq. 4; docs/reference_code.md#ha2g-levels).
Losses: hierarchical Huber, NS-GAN on the last level, style diverging, KL, multi-level audio-text contrastive
and the bone-angle physical constraint (:mod:`beatlite.models.ha2g_losses`).

Ablations (paper Tables 3-4) are config switches, named in :data:`ABLATIONS`
(:mod:`beatlite.models.ha2g_ablations`, which lists the paper row of each).

Inference follows one of two protocols (:meth:`HA2G.generate`): ``"deterministic"`` (z = mu
of the true speaker; beatlite's tables) or ``"sampled"`` (HA2G's evaluation code: a random
training speaker per window and a sampled z, seeded by a ``torch.Generator``).

Call :meth:`HA2G.prepare` with the training windows before training (``fit`` does): it
stores the mean direction vectors and the bone-angle statistics of the physical constraint
as buffers (saved in the checkpoint's state dict).

Differences from the reference, on purpose: the discriminator returns logits (NS-GAN through
``logsigmoid``); the contrastive logits ``1 / distance`` have the distance floored at
``contrastive_min_distance``; the text encoders use learned word embeddings (no FastText); the
spectrogram is scaled by ``mel / 40 + 1`` before the first convolution. The output heads and
the discriminator use ``LeakyReLU(slope)``: the reference's ``nn.LeakyReLU(inplace=True)`` has
PyTorch's default slope 0.01, the presets' value (checkpoints trained before used 0.1).

Taught in notebooks/06_ha2g.ipynb, sections 2 (the coarse-to-fine body hierarchy) to 8 (generation and evaluation).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import numpy as np
import torch
from torch import nn

from beatlite.constants import N_SPEAKERS
from beatlite.data.normalize import Normalizers
from beatlite.metrics.consistency import default_angle_pairs
from beatlite.models.base import (
    N_PRE,
    AdversarialConfig,
    Batch,
    GestureModel,
    TextConfig,
    check_batch,
    evaluating,
    window_chunks,
)
from beatlite.models.ha2g_ablations import ABLATIONS
from beatlite.models.ha2g_audio import AUDIO_LEVELS, HierarchicalAudioEncoder, StyleCoordinator, blend_audio
from beatlite.models.ha2g_losses import (
    N_BONES,
    angle_statistics,
    bone_angles,
    hierarchical_huber,
    multilevel_contrastive_loss,
    physical_constraint_loss,
    style_diverging_loss,
)
from beatlite.models.layers import (
    ConvDiscriminator,
    TextEncoderTCN,
    check_ids,
    kl_standard_normal,
    ns_gan_d_loss,
    ns_gan_g_loss,
    reparameterize,
    sum_directions,
)

AUDIO_MODES = ("blend", *AUDIO_LEVELS)
STYLES = ("reference", "shared")
"""Values of :attr:`HA2GConfig.style` (see the module docstring)."""
PROTOCOLS = ("deterministic", "sampled")
"""Inference protocols of :meth:`HA2G.generate`."""
RETIRED_FIELDS = ("d_lr_scale",)
"""Config fields of older checkpoints that are ignored on load (the discriminator's learning rate
is :attr:`beatlite.train.TrainConfig.d_lr_weight`)."""


@dataclasses.dataclass
class HA2GConfig(TextConfig, AdversarialConfig):
    """HA2G hyper-parameters (defaults + the ``paper`` preset = HA2G's code, docs/reference_code.md#ha2g-hyperparameters).

    ``style``: ``"reference"`` (separate coordinator embedding, per-level style codes) or
    ``"shared"`` (one z for everything); the default ``"shared"`` is what checkpoints saved
    before the field existed were trained with, the presets set ``"reference"``.
    Switches: ``hierarchical`` (False = "holistic": one level with all 42 bones),
    ``body_hierarchy`` / ``hand_hierarchy`` (False: the body bones (spine to wrists) / the finger
    bones in one level instead of 3), ``audio_mode`` (``"blend"`` = style-coordinated mix of the
    3 levels; ``"low"``/``"mid"``/``"high"`` = that level only), ``same_audio`` (one coordinator
    column shared by every body level), ``use_text`` (word input), ``use_contrastive`` (needs
    ``use_text``), ``contrastive_high_negatives`` (False: the positive term has no other
    high-level features as negatives), ``use_physical``, ``adversarial``, ``use_style_loss``.
    ``no_adv_epochs`` is the 0-based epoch from which the GAN term is on (reference: epoch >
    ``loss_warmup`` = 10). ``slope`` is the LeakyReLU slope of the output heads and the
    discriminator (reference 0.01). ``audio_freq_stride`` is the frequency stride of the audio
    learner's first convolution (reference 1; ``tiny`` 2). ``audio_order`` its layer order: ``"beatlite"``
    (conv -> BN -> ReLU) or ``"reference"`` (HA2G's code: conv -> ReLU -> BN, biased stem, ReLU and BN after each
    stream's convolution; docs/reference_code.md#ha2g-audio, where the difference is measured).
    """

    preset: str = "paper"
    text_per_level: bool = True
    n_speakers: int = N_SPEAKERS
    z_dim: int = 16
    style_hidden: int = 32
    audio_channels: tuple[int, ...] = (32, 64, 128, 256)
    audio_blocks: tuple[int, ...] = (3, 4, 6, 3)
    se_reduction: int = 8
    audio_features: int = 32
    audio_freq_stride: int = 1
    audio_order: str = "beatlite"
    hidden: int = 300
    n_layers: int = 4
    dropout: float = 0.3
    slope: float = 0.01
    style: str = "shared"
    hierarchical: bool = True
    body_hierarchy: bool = True
    hand_hierarchy: bool = True
    audio_mode: str = "blend"
    same_audio: bool = False
    use_text: bool = True
    use_contrastive: bool = True
    contrastive_high_negatives: bool = True
    use_physical: bool = True
    use_style_loss: bool = True
    huber_weight: float = 250.0
    huber_beta: float = 0.1
    adv_weight: float = 5.0
    no_adv_epochs: int = 11
    kld_weight: float = 0.1
    style_weight: float = 0.05
    style_beta: float = 0.05
    style_clip: float = 1000.0
    contrastive_pos_weight: float = 0.2
    contrastive_neg_weight: float = 0.005
    contrastive_min_distance: float = 1e-2
    physical_weight: float = 0.01
    angle_var_floor: float = 1e-4

    def __post_init__(self) -> None:
        self.audio_channels = tuple(int(c) for c in self.audio_channels)
        self.audio_blocks = tuple(int(c) for c in self.audio_blocks)
        if len(self.audio_channels) != 4 or len(self.audio_blocks) != 4:
            raise ValueError(
                f"audio_channels and audio_blocks must have 4 entries, got {self.audio_channels} "
                f"and {self.audio_blocks}"
            )
        if self.audio_mode not in AUDIO_MODES:
            raise ValueError(f"audio_mode must be one of {AUDIO_MODES}, got {self.audio_mode!r}")
        if self.style not in STYLES:
            raise ValueError(f"style must be one of {STYLES}, got {self.style!r}")
        if self.use_contrastive and not self.use_text:
            raise ValueError("use_contrastive needs use_text (the contrastive loss aligns text and audio)")
        if self.n_frames <= N_PRE + 6:
            raise ValueError(f"n_frames must be > {N_PRE + 6}, got {self.n_frames}")
        for name in ("vocab_size", "n_speakers", "z_dim", "hidden", "n_layers", "audio_features"):
            if int(getattr(self, name)) < 1:
                raise ValueError(f"{name} must be >= 1, got {getattr(self, name)}")


PRESETS: dict[str, dict[str, Any]] = {
    "paper": {"style": "reference"},
    "tiny": {
        "style": "reference",
        "vocab_size": 1000,
        "word_dim": 16,
        "text_hidden": 24,
        "text_layers": 2,
        "text_features": 16,
        "text_per_level": False,
        "z_dim": 8,
        "style_hidden": 16,
        "audio_channels": (4, 8, 16, 32),
        "audio_blocks": (1, 1, 1, 1),
        "se_reduction": 4,
        "audio_features": 16,
        "audio_freq_stride": 2,
        "hidden": 48,
        "n_layers": 1,
        "dropout": 0.1,
        "no_adv_epochs": 4,
        "d_hidden": 32,
        "d_layers": 1,
    },
}
"""Preset name -> overrides of :class:`HA2GConfig` (``paper``: HA2G's code, docs/reference_code.md#ha2g-hyperparameters; ``tiny``: CPU minutes).

``tiny``'s GRUs have 48 units: with 32, training from seed 1 reached a validation FGD of 5.7 in
30 epochs and a test FGD of 7.19; with 48 the same seed reached 3.28 and 4.60 (issue 6 notes),
for about 15 % more time per epoch. Its audio stem has a frequency stride of 2
(``audio_freq_stride``), as the "fast" SE-ResNet-34 of the voxceleb_trainer repository that the
reference's ResNetSE34V2 comes from (a stride-(2, 1) first convolution): the 4-channel first layer
then runs on 64 x 70 instead of 128 x 70, and the audio learner's training step takes about 2.5x
less time (37 vs 93 ms for 32 windows on 2 threads).
"""


def body_levels(hierarchical: bool = True, *, body: bool = True, hand: bool = True) -> list[np.ndarray]:
    """Bone indices of each body level.

    Parameters
    ----------
    hierarchical : bool
        True: the levels of ``beatlite.skeleton.ted.HA2G_LEVELS`` (8/10/12/22/32/42 bones);
        False: one level with all 42 bones ("holistic", paper Table 4).
    body : bool
        False ("w/o body hierarchy"): the body bones up to the wrists in one level (HA2G level 3)
        instead of levels 1-3.
    hand : bool
        False ("w/o hand hierarchy"): every finger bone at once (HA2G level 6) instead of
        levels 4-6.

    Returns
    -------
    list of (K_l,) int64 arrays, each level a superset of the previous one.

    Examples
    --------
    Bones per level (each bone is 3 channels of ``dirvec126``): six levels coarse to fine, one holistic level,
    or four without the body hierarchy; every level keeps the bones of the one before.

    >>> from beatlite.models.ha2g import body_levels
    >>> [len(level) for level in body_levels()]
    [8, 10, 12, 22, 32, 42]
    >>> [len(level) for level in body_levels(False)], [len(level) for level in body_levels(body=False)]
    ([42], [12, 22, 32, 42])
    >>> levels = body_levels()
    >>> all(set(a) <= set(b) for a, b in zip(levels, levels[1:]))
    True
    """
    if not hierarchical:
        return [np.arange(N_BONES, dtype=np.int64)]
    from beatlite.skeleton import ted

    chosen = ([0, 1, 2] if body else [2]) + ([3, 4, 5] if hand else [5])
    return [np.asarray(ted.HA2G_LEVELS[k], dtype=np.int64) for k in chosen]


def _bone_columns(bones: np.ndarray) -> np.ndarray:
    """(K,) bone ids -> (3K,) channel columns of the 126-d vector (bone-major, x y z)."""
    return (3 * bones[:, None] + np.arange(3)[None, :]).reshape(-1)


class LevelGenerator(nn.Module):
    """One body level's pose generator (``Hierarchical_PoseGenerator``).

    ``cat[pre_seq (D+1), audio F_a, text F_t, z Z] -> bidirectional GRU (directions summed)
    -> Linear(H, H/2) -> LeakyReLU(slope) -> Linear(H/2, D)`` (reference slope 0.01;
    ``F_t = 0`` without text).

    Shapes
    ------
    pre_seq (B, T, D+1), audio (B, T, F_a), text (B, T, F_t), z (B, Z) -> (B, T, D)

    Examples
    --------
    The first level (8 bones, D = 24) with 16 audio features, no text and an 8-channel style code: the
    GRU reads ``25 + 16 + 0 + 8 = 49`` channels per frame.

    >>> import torch
    >>> from beatlite.models.ha2g import LevelGenerator
    >>> _ = torch.manual_seed(0)
    >>> net = LevelGenerator(49, 24, hidden=32, n_layers=1, dropout=0.0, slope=0.01)
    >>> out = net(torch.zeros(2, 34, 25), torch.zeros(2, 34, 16), torch.zeros(2, 34, 0), torch.zeros(2, 8))
    >>> tuple(out.shape)
    (2, 34, 24)
    """

    def __init__(
        self, in_features: int, out_dim: int, hidden: int, n_layers: int, dropout: float, slope: float
    ) -> None:
        super().__init__()
        self.hidden = hidden
        self.gru = nn.GRU(
            in_features,
            hidden,
            num_layers=n_layers,
            batch_first=True,
            bidirectional=True,
            dropout=dropout if n_layers > 1 else 0.0,
        )
        half = max(1, hidden // 2)
        self.head = nn.Sequential(nn.Linear(hidden, half), nn.LeakyReLU(slope), nn.Linear(half, out_dim))

    def forward(
        self, pre_seq: torch.Tensor, audio: torch.Tensor, text: torch.Tensor, z: torch.Tensor
    ) -> torch.Tensor:
        zt = z[:, None, :].expand(-1, pre_seq.shape[1], -1)
        seq, _ = self.gru(torch.cat([pre_seq, audio, text, zt], dim=-1))
        return self.head(sum_directions(seq, self.hidden))


def reparameterise(
    mu: torch.Tensor, logvar: torch.Tensor, sample: bool, generator: torch.Generator | None = None
) -> torch.Tensor:
    """``mu + eps * exp(logvar / 2)`` with ``eps ~ N(0, I)`` (drawn from ``generator`` if given) or ``mu``.

    Parameters
    ----------
    mu, logvar : (...) float tensors
        Means and natural-log variances.
    sample : bool
        Draw (True) or return ``mu`` (False: evaluation's z = mu).
    generator : torch.Generator, optional

    Returns
    -------
    (...) float tensor, units of ``mu``.

    Examples
    --------
    Around 1 with variance 4: ``mu`` when not sampling; sampled, a standard deviation of 2 (10000 draws,
    one decimal); the same generator seed gives the same draw.

    >>> import math, torch
    >>> from beatlite.models.ha2g import reparameterise
    >>> mu, logvar = torch.ones(10000), torch.full((10000,), math.log(4.0))
    >>> torch.equal(reparameterise(mu, logvar, False), mu)
    True
    >>> z = reparameterise(mu, logvar, True, torch.Generator().manual_seed(0))
    >>> round(float(z.mean()), 1), round(float(z.std()), 1)
    (1.0, 2.0)
    >>> torch.equal(reparameterise(mu, logvar, True, torch.Generator().manual_seed(0)), z)
    True
    """
    if not sample:
        return mu
    if generator is None:
        eps = torch.randn_like(mu)
    else:
        eps = torch.randn(mu.shape, generator=generator, dtype=mu.dtype, device=mu.device)
    return reparameterize(mu, logvar, eps)


class SpeakerStyle(nn.Module):
    """A level generator's own style code (reference design): ``Embedding -> Linear -> (mu, logvar)``.

    Shapes
    ------
    speaker (B,) int64 -> mu, logvar, z (B, Z); z is sampled when ``sample`` else ``mu``.

    Examples
    --------
    >>> import torch
    >>> from beatlite.models.ha2g import SpeakerStyle
    >>> _ = torch.manual_seed(0)
    >>> mu, logvar, z = SpeakerStyle(n_speakers=4, z_dim=8)(torch.tensor([0, 3]), sample=False)
    >>> tuple(mu.shape), tuple(logvar.shape), torch.equal(z, mu)
    ((2, 8), (2, 8), True)
    """

    def __init__(self, n_speakers: int, z_dim: int) -> None:
        super().__init__()
        self.embedding = nn.Sequential(nn.Embedding(n_speakers, z_dim), nn.Linear(z_dim, z_dim))
        self.mu = nn.Linear(z_dim, z_dim)
        self.logvar = nn.Linear(z_dim, z_dim)

    def forward(
        self, speaker: torch.Tensor, sample: bool, generator: torch.Generator | None = None
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        h = self.embedding(speaker)
        mu, logvar = self.mu(h), self.logvar(h)
        return mu, logvar, reparameterise(mu, logvar, sample, generator)


class HA2GDiscriminator(ConvDiscriminator):
    """HA2G's ``Hierarchical_ConvDiscriminator`` on the last level (126 channels), returning logits.

    The CaMN/Trimodal :class:`~beatlite.models.layers.ConvDiscriminator` with a bidirectional
    GRU in place of the LSTM (directions summed), ``Linear(hidden, 1)`` per frame,
    ``Linear(T - 6, 1)`` over time.

    Shapes
    ------
    (B, T, D) -> (B, 1) logits (``sigmoid`` = the reference's probability of "real").

    Examples
    --------
    >>> import torch
    >>> from beatlite.models.ha2g import HA2GDiscriminator
    >>> _ = torch.manual_seed(0)
    >>> d = HA2GDiscriminator(126, hidden=16, n_layers=1, n_frames=34, slope=0.01)
    >>> tuple(d(torch.zeros(3, 34, 126)).shape)
    (3, 1)
    """

    def __init__(self, input_dim: int, hidden: int, n_layers: int, n_frames: int, slope: float) -> None:
        super().__init__(
            input_dim, hidden=hidden, n_layers=n_layers, n_frames=n_frames, slope=slope, rnn="gru"
        )


class HA2G(GestureModel):
    """Hierarchical Audio-to-Gesture on TED-43 direction vectors (see the module docstring).

    Parameters
    ----------
    config : HA2GConfig

    ``forward(batch, *, sample_style=None, generator=None)`` returns
        ``"pose"`` (B, T, 126) the last level's prediction in the 126-d layout;
        ``"level0"`` ... ``"level{H-1}"`` (B, T, D_k) every level's prediction (bones of
        :func:`body_levels`);
        ``"mu"``, ``"logvar"``, ``"z"`` (B, Z) the KL-regularised style distribution and code
        (``"shared"``: the one z; ``"reference"``: the last level's);
        ``"z_levels"`` (B, H, Z) the code each level generator read;
        ``"style_weights"`` (B, 3, H) audio-level weights per body level;
        ``"audio_low"`` / ``"audio_mid"`` / ``"audio_high"`` (B, T, F) the levels computed;
        ``"text0"``... (B, T, F_t) the generators' text features and ``"text_contrast"`` the
        contrastive ones (when used);
        in training mode with ``use_style_loss``: ``"z_other"`` (B, Z) / ``"z_levels_other"``
        (B, H, Z) other speakers' codes and ``"pose_other"`` (B, T, 126) the last level's
        prediction with them (the style diverging loss' second output, decoded in the same
        cascade pass as a batch of 2B).
        Codes are sampled when ``sample_style`` (default: in training mode), from
        ``generator`` when given.

    Examples
    --------
    A tiny HA2G on two fake windows: one prediction per body level (3 channels per bone of
    :func:`body_levels`), the last level in the 126-channel layout, and the coordinator's weights of the low,
    mid and high audio levels sum to 1 for every body level.

    >>> import torch
    >>> from beatlite.models.ha2g import build_ha2g
    >>> from beatlite.models.testing import fake_batch
    >>> _ = torch.manual_seed(0)
    >>> model = build_ha2g("tiny").eval()
    >>> batch = {k: v for k, v in fake_batch(2, vocab_size=1000).items() if k in model.input_keys}
    >>> out = model(batch)
    >>> tuple(out["pose"].shape), [out[f"level{k}"].shape[-1] for k in range(model.n_levels)]
    ((2, 34, 126), [24, 30, 36, 66, 96, 126])
    >>> tuple(out["style_weights"].shape), bool(torch.allclose(out["style_weights"].sum(1), torch.ones(2, 6)))
    ((2, 3, 6), True)

    The ``"deterministic"`` protocol (z = mu of the batch's speakers) gives the same pose every call:

    >>> torch.equal(model.generate(batch), model.generate(batch))
    True
    """

    name = "ha2g"
    representation = "dirvec126"
    config_class = HA2GConfig

    @classmethod
    def keys_for(cls, config: HA2GConfig) -> tuple[str, ...]:
        """Batch keys read with ``config`` (no ``"word"`` without text)."""
        return ("mel", "word", "speaker", "dirvec") if config.use_text else ("mel", "speaker", "dirvec")

    @property
    def input_keys(self) -> tuple[str, ...]:  # type: ignore[override]
        """Batch keys the forward pass reads (:meth:`keys_for` of its config)."""
        return self.keys_for(self.config)

    def __init__(self, config: HA2GConfig) -> None:
        super().__init__(config)
        c = config
        levels = body_levels(c.hierarchical, body=c.body_hierarchy, hand=c.hand_hierarchy)
        if not np.array_equal(np.sort(levels[-1]), np.arange(N_BONES)):
            raise ValueError("the last body level must hold all 42 bones")
        self.n_levels = len(levels)
        self.level_dims: tuple[int, ...] = tuple(3 * len(lv) for lv in levels)
        self._level_columns(levels)
        # the modules are built in this order (it fixes the initial weights of a seed)
        self._audio_modules(c)
        self._style_modules(c)
        self._text_modules(c)
        text_features = c.text_features if c.use_text else 0
        width = 1 + c.audio_features + text_features + c.z_dim
        self.generators = nn.ModuleList(
            [LevelGenerator(d + width, d, c.hidden, c.n_layers, c.dropout, c.slope) for d in self.level_dims]
        )
        if c.adversarial:
            self.discriminator = HA2GDiscriminator(3 * N_BONES, c.d_hidden, c.d_layers, c.n_frames, c.slope)
        self._statistic_buffers(c)

    def _level_columns(self, levels: list[np.ndarray]) -> None:
        """Buffers ``_cols{k}`` (level k's columns) and ``_dst{k}``/``_src{k}`` (channels shared with level k-1)."""
        for k, lv in enumerate(levels):
            self.register_buffer(f"_cols{k}", torch.as_tensor(_bone_columns(lv)), persistent=False)
            if not k:
                continue
            prev = {int(b): i for i, b in enumerate(levels[k - 1])}
            dst = [i for i, b in enumerate(lv) if int(b) in prev]
            src = [prev[int(lv[i])] for i in dst]
            for name, index in ((f"_dst{k}", dst), (f"_src{k}", src)):
                columns = torch.as_tensor(_bone_columns(np.asarray(index, dtype=np.int64)))
                self.register_buffer(name, columns, persistent=False)

    def _audio_modules(self, c: HA2GConfig) -> None:
        """The hierarchical audio learner (only the levels used) and the style coordinator."""
        needed = set(AUDIO_LEVELS) if c.audio_mode == "blend" else {c.audio_mode}
        if c.use_contrastive:
            needed |= {"low", "high"}
        self.audio = HierarchicalAudioEncoder(
            c.audio_channels, c.audio_blocks, c.se_reduction, c.audio_features, sorted(needed), c.n_frames,
            c.audio_freq_stride, c.audio_order,
        )  # fmt: skip
        self.coordinator: StyleCoordinator | None = None
        if c.audio_mode == "blend":
            self.coordinator = StyleCoordinator(c.z_dim, c.style_hidden, 1 if c.same_audio else self.n_levels)

    def _style_modules(self, c: HA2GConfig) -> None:
        """``style="shared"``: one sampled style for everything; ``"reference"``: the coordinator's own
        speaker embedding and one style code per level."""
        if c.style == "shared":
            self.speaker_embedding = nn.Sequential(
                nn.Embedding(c.n_speakers, c.z_dim), nn.Linear(c.z_dim, c.z_dim), nn.LeakyReLU(c.slope)
            )
            self.speaker_mu = nn.Linear(c.z_dim, c.z_dim)
            self.speaker_logvar = nn.Linear(c.z_dim, c.z_dim)
            return
        self.coordinator_embedding = (
            nn.Sequential(nn.Embedding(c.n_speakers, c.z_dim), nn.Linear(c.z_dim, c.z_dim))
            if self.coordinator is not None
            else None
        )
        self.level_styles = nn.ModuleList([SpeakerStyle(c.n_speakers, c.z_dim) for _ in range(self.n_levels)])

    def _text_modules(self, c: HA2GConfig) -> None:
        """The text encoders (one per level or one shared) and the contrastive loss's own."""

        def text_encoder() -> TextEncoderTCN:
            return TextEncoderTCN(
                c.vocab_size, c.word_dim, c.text_hidden, c.text_layers, c.text_features, c.dropout
            )

        n_text = (self.n_levels if c.text_per_level else 1) if c.use_text else 0
        self.text_encoders = nn.ModuleList([text_encoder() for _ in range(n_text)])
        self.contrastive_text = text_encoder() if c.use_contrastive else None

    def _statistic_buffers(self, c: HA2GConfig) -> None:
        """Data statistics (set by prepare / set_statistics; saved in the state dict)."""
        pairs = default_angle_pairs() if c.use_physical else np.zeros((0, 2), dtype=np.int64)
        self.register_buffer("angle_pairs", torch.as_tensor(pairs), persistent=False)
        self.register_buffer("mean_dirvec", torch.zeros(3 * N_BONES))
        self.register_buffer("angle_mean", torch.zeros(len(pairs)))
        self.register_buffer("angle_var", torch.ones(len(pairs)))
        self.register_buffer("angle_change", torch.ones(len(pairs)))
        self.register_buffer("statistics_ready", torch.zeros((), dtype=torch.bool))
        # the flag as a Python bool too, so that the losses check it without reading the device
        self._ready = False
        self.register_load_state_dict_post_hook(HA2G._read_ready)

    @staticmethod
    def _read_ready(module: nn.Module, _keys: Any) -> None:
        module._ready = bool(module.statistics_ready)

    # ------------------------------------------------------------------ data statistics
    def set_statistics(
        self, mean_dirvec: np.ndarray, dirvec_windows: np.ndarray | Iterable[np.ndarray] | None = None
    ) -> None:
        """Store the mean direction vector and (when ``use_physical``) the angle statistics.

        Parameters
        ----------
        mean_dirvec : (126,) float
            The training mean subtracted from the unit direction vectors.
        dirvec_windows : (N, T, 126) float or an iterable of (N_i, T, 126) chunks, optional
            Training windows (``windows["dirvec"]``); required when ``use_physical``.
        """
        m = np.asarray(mean_dirvec, dtype=np.float64)
        if m.shape != (3 * N_BONES,) or not np.all(np.isfinite(m)):
            raise ValueError(f"mean_dirvec must be (126,) finite, got shape {m.shape}")
        with torch.no_grad():
            self.mean_dirvec.copy_(torch.as_tensor(m, dtype=self.mean_dirvec.dtype))
            if self.config.use_physical:
                if dirvec_windows is None:
                    raise ValueError("set_statistics: dirvec_windows is required when use_physical is on")
                stats = angle_statistics(
                    dirvec_windows, m, pairs=self.angle_pairs.numpy(), var_floor=self.config.angle_var_floor
                )
                self.angle_mean.copy_(torch.as_tensor(stats.mean))
                self.angle_var.copy_(torch.as_tensor(stats.var))
                self.angle_change.copy_(torch.as_tensor(stats.change))
            self.statistics_ready.fill_(True)
        self._ready = True

    def prepare(self, train_windows: Any, normalizers: Normalizers | None = None) -> None:
        """Compute the data statistics from the training windows (called by ``fit``).

        ``train_windows`` is a numpy window dict or a window store view (``StoreWindows``, whose
        ``dirvec`` is read in chunks, so memory stays flat). The mean direction vector the windows
        were centred with is ``normalizers.dirvec.mean`` (the train split's
        :class:`~beatlite.data.normalize.Normalizers`, which ``fit`` passes).
        """
        if "dirvec" not in train_windows:
            raise KeyError(
                f"HA2G.prepare: train_windows has no 'dirvec' (keys: {sorted(train_windows.keys())})"
            )
        if normalizers is None:
            raise ValueError(
                "HA2G.prepare needs the train split's Normalizers (fit passes Windows.normalizers, or "
                "meta=normalizers.to_meta()): it adds the mean direction back for its angle statistics"
            )
        self.set_statistics(normalizers.dirvec.mean, window_chunks(train_windows, "dirvec"))

    def word_embeddings(self) -> list[nn.Embedding]:
        """The embedding of every text encoder (the generators' and the contrastive loss's)."""
        extra = [] if self.contrastive_text is None else [self.contrastive_text]
        return [enc.embedding for enc in (*self.text_encoders, *extra)]

    # ------------------------------------------------------------------ forward
    def _check_inputs(self, batch: Batch) -> None:
        check_batch(batch, self.input_keys, "HA2G")
        b = batch["dirvec"].shape[0]
        t = self.config.n_frames
        want = {"dirvec": (b, t, 3 * N_BONES), "speaker": (b,)}
        if self.config.use_text:
            want["word"] = (b, t)
        for key, shape in want.items():
            if tuple(batch[key].shape) != shape:
                raise ValueError(
                    f"HA2G: batch[{key!r}] must have shape {shape}, got {tuple(batch[key].shape)}"
                )
        mel = batch["mel"]
        if mel.ndim != 3 or mel.shape[0] != b or mel.shape[2] != 128:
            raise ValueError(f"HA2G: batch['mel'] must be ({b}, M, 128), got {tuple(mel.shape)}")
        check_ids(batch["speaker"], self.config.n_speakers, "HA2G: speaker ids")

    def speaker_style(
        self, speaker: torch.Tensor, *, sample: bool | None = None, generator: torch.Generator | None = None
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Speaker ids (B,) -> (mu, logvar, z), each (B, Z): the KL-regularised style code.

        ``"shared"``: the one code of every level; ``"reference"``: the last level's. ``z`` is
        sampled when ``sample`` (default: in training mode), else ``mu``.
        """
        style = self._styles(speaker, self.training if sample is None else sample, generator)
        return style["mu"], style["logvar"], style["z"]

    def coordinator_weights(self, speaker: torch.Tensor) -> torch.Tensor:
        """Speaker ids (B,) -> (B, 3, H) weights of the low, mid and high audio levels for each of the H
        body levels (eq. 3; each column sums to 1), as evaluation uses them (no sampling).

        ``"reference"``: from the coordinator's own speaker embedding; ``"shared"``: from the mean style.
        A model without a coordinator (one audio level) gives that level weight 1 everywhere.
        """
        styles = self._styles(speaker, False)
        like = next(self.parameters())
        return self._style_weights(styles["coord"], len(speaker), like)

    def _styles(
        self, speaker: torch.Tensor, sample: bool, generator: torch.Generator | None = None
    ) -> dict[str, torch.Tensor | None]:
        """Speaker ids (B,) -> ``coord`` (B, Z) coordinator input (None without coordinator),
        ``levels`` (B, H, Z) each generator's code, ``mu``/``logvar``/``z`` (B, Z) the KL's."""
        if self.config.style == "shared":
            h = self.speaker_embedding(speaker)
            mu, logvar = self.speaker_mu(h), self.speaker_logvar(h)
            z = reparameterise(mu, logvar, sample, generator)
            levels = z[:, None, :].expand(-1, self.n_levels, -1)
            return {"coord": z, "levels": levels, "mu": mu, "logvar": logvar, "z": z}
        codes = [style(speaker, sample, generator) for style in self.level_styles]
        coord = None if self.coordinator_embedding is None else self.coordinator_embedding(speaker)
        mu, logvar, z = codes[-1]
        return {
            "coord": coord,
            "levels": torch.stack([c[2] for c in codes], 1),
            "mu": mu,
            "logvar": logvar,
            "z": z,
        }

    def _style_weights(self, coord: torch.Tensor | None, b: int, like: torch.Tensor) -> torch.Tensor:
        """Coordinator input (B, Z) -> (B, 3, H) audio-level weights (one-hot for a single audio level)."""
        if self.coordinator is None or coord is None:
            w = like.new_zeros(b, 3, self.n_levels)
            w[:, AUDIO_LEVELS.index(self.config.audio_mode)] = 1.0
            return w
        w = self.coordinator(coord)
        return w.expand(-1, -1, self.n_levels) if self.config.same_audio else w

    def _decode(
        self,
        dirvec: torch.Tensor,
        audio: dict[str, torch.Tensor],
        texts: list[torch.Tensor],
        coord: torch.Tensor | None,
        levels: torch.Tensor,
    ) -> tuple[list[torch.Tensor], torch.Tensor]:
        """Run the cascade of level generators; returns (per-level predictions, style weights).

        ``coord`` (B, Z) is the coordinator's input, ``levels`` (B, H, Z) the generators' codes.
        """
        b, t, _ = dirvec.shape
        weights = self._style_weights(coord, b, dirvec)
        full = {lv: audio.get(lv, audio[next(iter(audio))]) for lv in AUDIO_LEVELS}
        level_audio = blend_audio(full, weights)  # (B, H, T, F)
        n_pre = self.n_pre
        no_text = dirvec.new_zeros(b, t, 0)
        preds: list[torch.Tensor] = []
        for k, gen in enumerate(self.generators):
            cols = getattr(self, f"_cols{k}")
            d = self.level_dims[k]
            seed = torch.cat([dirvec[:, :n_pre, cols], dirvec.new_ones(b, n_pre, 1)], dim=-1)
            rest = dirvec.new_zeros(b, t - n_pre, d + 1)
            if k:
                dst, src = getattr(self, f"_dst{k}"), getattr(self, f"_src{k}")
                # under autocast the prediction may be bfloat16: index_copy needs one dtype (CUDA)
                rest = rest.index_copy(-1, dst, preds[-1][:, n_pre:, src].to(rest.dtype))
            pre_seq = torch.cat([seed, rest], dim=1)
            text = (texts[k] if len(texts) > 1 else texts[0]) if texts else no_text
            preds.append(gen(pre_seq, level_audio[:, k], text, levels[:, k]))
        return preds, weights

    def forward(
        self, batch: Batch, *, sample_style: bool | None = None, generator: torch.Generator | None = None
    ) -> dict[str, torch.Tensor]:
        """See the class docstring; reads ``mel``, ``word``, ``speaker`` and seed frames of ``dirvec``."""
        self._check_inputs(batch)
        dirvec = batch["dirvec"]
        audio = self.audio(batch["mel"])
        sample = self.training if sample_style is None else bool(sample_style)
        style = self._styles(batch["speaker"], sample, generator)
        texts = [enc(batch["word"]) for enc in self.text_encoders]
        b = dirvec.shape[0]
        if self.training and self.config.use_style_loss:
            # the style diverging loss needs the cascade run again with other speakers' codes:
            # both runs go through the cascade as one batch of 2B (same result, half the
            # per-time-step GRU calls)
            coord_other, other_style = self._other_style(batch["speaker"], style, sample)
            coord = None if style["coord"] is None else torch.cat([style["coord"], coord_other])
            both, weights = self._decode(
                dirvec.repeat(2, 1, 1),
                {lv: f.repeat(2, 1, 1) for lv, f in audio.items()},
                [text.repeat(2, 1, 1) for text in texts],
                coord,
                torch.cat([style["levels"], other_style["levels"]]),
            )
            preds, weights = [p[:b] for p in both], weights[:b]
            other = {
                "pose_other": both[-1][b:],
                "z_other": other_style["z"],
                "z_levels_other": other_style["levels"],
            }
        else:
            preds, weights = self._decode(dirvec, audio, texts, style["coord"], style["levels"])
            other = {}
        pose = dirvec.new_zeros(dirvec.shape).index_copy(
            -1, getattr(self, f"_cols{self.n_levels - 1}"), preds[-1].to(dirvec.dtype)
        )
        out: dict[str, torch.Tensor] = {
            "pose": pose,
            "mu": style["mu"],
            "logvar": style["logvar"],
            "z": style["z"],
            "z_levels": style["levels"],
            "style_weights": weights,
        }
        out.update({f"level{k}": p for k, p in enumerate(preds)})
        out.update({f"audio_{lv}": f for lv, f in audio.items()})
        for k, text in enumerate(texts):
            out[f"text{k}"] = text
        if self.contrastive_text is not None:
            out["text_contrast"] = self.contrastive_text(batch["word"])
        out.update(other)
        return out

    def _other_style(
        self, speaker: torch.Tensor, style: dict[str, Any], sample: bool
    ) -> tuple[torch.Tensor | None, dict[str, Any]]:
        """The style diverging loss' other speakers: (coordinator input, their styles).

        ``"reference"``: a permutation of the batch's speakers, the coordinator input unchanged
        (HA2G's code reuses the blended audio of the true speakers); ``"shared"``: uniformly
        random speaker ids, driving the coordinator too.
        """
        if self.config.style == "shared":
            ids = torch.randint(0, self.config.n_speakers, speaker.shape, device=speaker.device)
            other = self._styles(ids, sample)
            return other["coord"], other
        # gather, the same values as speaker[perm]: inductor's pattern for indexing with a whole random
        # permutation fails (BackendCompilerFailed, torch 2.11 on an H200 and 2.13 on the CPU)
        perm = torch.randperm(speaker.shape[0], device=speaker.device)
        other = self._styles(speaker.gather(0, perm), sample)
        return style["coord"], other

    @torch.no_grad()
    def generate(
        self,
        batch: Batch,
        *,
        protocol: str = "deterministic",
        speakers: Sequence[int] | torch.Tensor | None = None,
        generator: torch.Generator | None = None,
    ) -> torch.Tensor:
        """Inference seeded by the first ``n_pre`` frames of ``batch["dirvec"]`` (see :class:`GestureModel`).

        Parameters
        ----------
        batch : dict of tensors
            A window batch; frames ``>= n_pre`` of ``"dirvec"`` are zeroed before the forward pass.
        protocol : "deterministic" or "sampled"
            ``"deterministic"`` (beatlite's tables): the batch's speakers, z = mu.
            ``"sampled"`` (HA2G's evaluation code): each window gets a speaker drawn uniformly
            from ``speakers`` and sampled style codes (z = mu + eps sigma), dropout off.
        speakers : sequence of int, required for ``"sampled"``
            The training speakers' ids to draw from.
        generator : torch.Generator, optional
            Source of the ``"sampled"`` draws (speakers, then eps): the same seed gives the same
            output; default torch's global generator.

        Returns
        -------
        (B, T, 126) float tensor
        """
        if protocol not in PROTOCOLS:
            raise ValueError(f"protocol must be one of {PROTOCOLS}, got {protocol!r}")
        if protocol == "deterministic":
            return super().generate(batch)
        if speakers is None:
            raise ValueError('protocol "sampled" needs speakers= (the training speaker ids to draw from)')
        pool = torch.as_tensor(speakers, dtype=torch.int64).reshape(-1)
        if pool.numel() == 0 or int(pool.min()) < 0 or int(pool.max()) >= self.config.n_speakers:
            raise ValueError(
                f"speakers must be non-empty ids in [0, {self.config.n_speakers}), got {pool.tolist()}"
            )
        check_batch(batch, ("dirvec",), "HA2G.generate")
        seeded = dict(batch)
        seeded["dirvec"] = batch["dirvec"].clone()
        seeded["dirvec"][:, self.n_pre :] = 0.0
        pick = torch.randint(0, pool.numel(), (seeded["dirvec"].shape[0],), generator=generator)
        seeded["speaker"] = pool[pick].to(seeded["dirvec"].device)
        with evaluating(self):
            return self.forward(seeded, sample_style=True, generator=generator)["pose"]

    @classmethod
    def from_config(cls, config: Mapping[str, Any]) -> GestureModel:
        """:meth:`GestureModel.from_config`, ignoring :data:`RETIRED_FIELDS` of older checkpoints."""
        return super().from_config({k: v for k, v in config.items() if k not in RETIRED_FIELDS})

    # ------------------------------------------------------------------ losses
    def losses(self, batch: Batch, out: dict[str, torch.Tensor], *, epoch: int) -> dict[str, torch.Tensor]:
        """Generator losses (unweighted terms plus the weighted ``"total"``).

        Keys: ``"huber"`` (sum over levels), ``"kld"``, and when switched on ``"adv"`` (only
        when :meth:`adversarial_active`), ``"style"``, ``"contrastive_pos"``/``"contrastive_neg"``,
        ``"physical"``. ``total = 250 huber + 5 adv + 0.1 kld + 0.05 style + 0.2 pos - 0.005 neg
        + 0.01 physical`` (weights from the config).
        """
        c = self.config
        target = batch["dirvec"]
        preds = [out[f"level{k}"] for k in range(self.n_levels)]
        targets = [target[..., getattr(self, f"_cols{k}")] for k in range(self.n_levels)]
        terms: dict[str, torch.Tensor] = {
            "huber": hierarchical_huber(preds, targets, beta=c.huber_beta),
            "kld": kl_standard_normal(out["mu"], out["logvar"]),
        }
        total = c.huber_weight * terms["huber"] + c.kld_weight * terms["kld"]
        if self.discriminator is not None and self.adversarial_active(epoch):
            terms["adv"] = ns_gan_g_loss(self.discriminator(out["pose"]))
            total = total + c.adv_weight * terms["adv"]
        if c.use_style_loss:
            terms["style"] = self._style_loss(batch, out)
            total = total + c.style_weight * terms["style"]
        if c.use_contrastive:
            audio = {lv: out[f"audio_{lv}"] for lv in ("low", "high")}
            con = multilevel_contrastive_loss(
                out["text_contrast"],
                audio,
                min_distance=c.contrastive_min_distance,
                high_negatives=c.contrastive_high_negatives,
            )
            terms["contrastive_pos"] = con["positive"]
            terms["contrastive_neg"] = con["negative"]
            total = (
                total
                + c.contrastive_pos_weight * con["positive"]
                - c.contrastive_neg_weight * con["negative"]
            )
        if c.use_physical:
            if not self._ready:
                raise RuntimeError(
                    "HA2G: call prepare(train_windows) before training (angle statistics unset)"
                )
            angles = bone_angles(out["pose"], self.mean_dirvec, self.angle_pairs)
            terms["physical"] = physical_constraint_loss(angles, self.angle_mean, self.angle_var)
            total = total + c.physical_weight * terms["physical"]
        terms["total"] = total
        return terms

    def _style_loss(self, batch: Batch, out: dict[str, torch.Tensor]) -> torch.Tensor:
        """Style diverging loss against the outputs for other speakers' style codes.

        Training-mode forward passes already carry them (``"pose_other"``, ``"z_other"``);
        otherwise (an eval-mode ``out``) the cascade is run here with new other speakers.
        """
        if "pose_other" in out:
            pose_other, z_other = out["pose_other"], out["z_other"]
        else:
            style = self._styles(batch["speaker"], self.training)
            coord, other = self._other_style(batch["speaker"], style, self.training)
            audio = {lv[6:]: v for lv, v in out.items() if lv.startswith("audio_")}
            texts = [out[f"text{k}"] for k in range(len(self.text_encoders))]
            pose_other = self._decode(batch["dirvec"], audio, texts, coord, other["levels"])[0][-1]
            z_other = other["z"]
        return style_diverging_loss(
            out[f"level{self.n_levels - 1}"],
            pose_other,
            out["z"],
            z_other,
            beta=self.config.style_beta,
            clip=self.config.style_clip,
            reference=self.config.style == "reference",
        )

    def discriminator_losses(self, batch: Batch, out: dict[str, torch.Tensor]) -> dict[str, torch.Tensor]:
        """NS-GAN discriminator loss on real ``dirvec`` vs the detached generated pose.

        ``"total" = "real" + "fake"`` with ``"real" = -mean log D(real)`` and
        ``"fake" = -mean log(1 - D(fake))`` (the last two detached, for logging).
        """
        if self.discriminator is None:
            raise RuntimeError("HA2G: adversarial is off, there is no discriminator")
        real = self.discriminator(batch["dirvec"])
        fake = self.discriminator(out["pose"].detach())
        return {
            "total": ns_gan_d_loss(real, fake),
            "real": -nn.functional.logsigmoid(real).mean().detach(),
            "fake": -nn.functional.logsigmoid(-fake).mean().detach(),
        }


def build_ha2g(preset: str = "tiny", ablation: str = "full", **overrides: Any) -> HA2G:
    """An HA2G model from a preset, an ablation switch name and further config overrides.

    Parameters
    ----------
    preset : str
        A key of :data:`PRESETS` (``"tiny"``, ``"paper"``).
    ablation : str
        A key of :data:`~beatlite.models.ha2g_ablations.ABLATIONS` (``"full"``: none).
    **overrides
        Fields of :class:`HA2GConfig` (they win over the ablation's).

    Examples
    --------
    The holistic ablation generates all 42 bones in one level; without text the model reads no words:

    >>> from beatlite.models.ha2g import build_ha2g
    >>> build_ha2g(ablation="holistic").level_dims
    (126,)
    >>> build_ha2g(ablation="no_text").input_keys
    ('mel', 'speaker', 'dirvec')
    """
    from beatlite.models.base import config_from_preset

    if ablation not in ABLATIONS:
        raise ValueError(f"ablation must be one of {sorted(ABLATIONS)}, got {ablation!r}")
    return HA2G(config_from_preset(HA2GConfig, PRESETS, preset, **{**ABLATIONS[ablation], **overrides}))
