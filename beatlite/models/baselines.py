"""Baselines with the :class:`~beatlite.models.base.GestureModel` interface (all ``euler141``).

- :class:`MeanPose` (floor row, not trained): every frame is the training-set mean pose.
- :class:`RandomClip` (reference row, not trained): real 34-frame training clips drawn at
  random, ignoring every input.
- :class:`S2G`: audio-only convolutional model in the style of Speech2Gesture
  (Ginosar et al. 2019): log-mel encoder + 1-D U-Net, no seed pose, regression + NS-GAN.
- :class:`Trimodal`: text + audio + speaker GRU in the style of Trimodal / MultiContext
  (Yoon et al. 2020; docs/reference_code.md#trimodal): 4-conv wave encoder, TCN text encoder, reparameterised
  speaker style z, bidirectional GRU (directions summed), seed pose.

Common objective of the learned baselines, as CaMN's (so differences come from the
architectures): ``rec_weight * Huber_0.1(pred, target)`` (no semantic weighting; at
z-scored error sizes Huber_0.1 is L1 minus 0.05, i.e. S2G's L1 loss) plus NS-GAN from
``no_adv_epochs`` on. Trimodal adds ``kld_weight * KLD`` of its speaker z; its
diversity regulariser is not implemented.

Taught in notebooks/07_benchmark.ipynb, section 1 (one evaluation, one common space: the baselines).
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
import torch
from torch import nn

from beatlite.constants import N_SPEAKERS, WINDOW_LENGTH
from beatlite.models.base import (
    AdversarialConfig,
    Batch,
    GestureModel,
    ModelConfig,
    TextConfig,
    check_batch,
    huber,
    seed_input,
    window_chunks,
    window_count,
    window_rows,
)
from beatlite.models.layers import (
    ConvDiscriminator,
    PlainWavEncoder,
    TextEncoderTCN,
    check_ids,
    kl_standard_normal,
    match_length,
    ns_gan_d_loss,
    ns_gan_g_loss,
    reparameterize,
    sum_directions,
)

POSE_DIM = 141


def _check_pose(batch: Batch, who: str) -> torch.Tensor:
    check_batch(batch, ("pose",), who)
    pose = batch["pose"]
    if pose.ndim != 3 or pose.shape[-1] != POSE_DIM:
        raise ValueError(f"{who}: batch['pose'] must be (B, T, {POSE_DIM}), got shape {tuple(pose.shape)}")
    return pose


def _checked_poses(pose: np.ndarray, who: str) -> np.ndarray:
    """``pose`` as float32 after checking it is (N > 0, T, 141)."""
    pose = np.asarray(pose, dtype=np.float32)
    if pose.ndim != 3 or pose.shape[-1] != POSE_DIM or pose.shape[0] == 0:
        raise ValueError(
            f"{who}.prepare: train_windows['pose'] must be (N>0, T, {POSE_DIM}), got {pose.shape}"
        )
    return pose


def _n_train_windows(train_windows: Any, who: str) -> int:
    """N of the training windows' ``pose`` (KeyError naming ``who`` without it)."""
    if "pose" not in train_windows:
        raise KeyError(f"{who}.prepare: train_windows has no 'pose' (keys: {sorted(train_windows.keys())})")
    return window_count(train_windows, "pose")


# ------------------------------------------------------------------------------------ untrained rows
@dataclasses.dataclass
class MeanPoseConfig(ModelConfig):
    """No options (the mean comes from :meth:`MeanPose.prepare`)."""


@dataclasses.dataclass
class RandomClipConfig(ModelConfig):
    """``n_clips`` training windows are kept (drawn with ``seed``); ``n_frames`` per clip."""

    n_clips: int = 32
    n_frames: int = WINDOW_LENGTH
    seed: int = 0


class _Untrained(GestureModel):
    """Shared parts of the two untrained rows: no generator parameters, zero loss."""

    input_keys = ("pose",)

    def losses(self, batch: Batch, out: dict[str, torch.Tensor], *, epoch: int) -> dict[str, torch.Tensor]:
        """``{"total": 0}`` (nothing to train)."""
        return {"total": out["pose"].new_zeros(())}


class MeanPose(_Untrained):
    """Frozen mean pose: ``forward`` returns the training mean (z-scored units) on every frame.

    ``prepare(train_windows)`` stores ``mean over windows and frames of train_windows["pose"]``;
    before it, the mean is 0 (the z-scoring mean).

    Shapes: ``batch["pose"]`` (B, T, 141) (only its shape and dtype are read) -> ``{"pose": (B, T, 141)}``.

    Examples
    --------
    Two training windows, one all 1 and one all 3: every generated frame is their mean, 2.

    >>> import numpy as np, torch
    >>> from beatlite.models import build_model
    >>> model = build_model("mean_pose")
    >>> model.prepare({"pose": np.stack([np.ones((34, 141)), np.full((34, 141), 3.0)])})
    >>> pose = model.generate({"pose": torch.zeros(2, 34, 141)})
    >>> tuple(pose.shape), torch.unique(pose).tolist()
    ((2, 34, 141), [2.0])
    """

    name = "mean_pose"
    representation = "euler141"
    config_class = MeanPoseConfig

    def __init__(self, config: MeanPoseConfig) -> None:
        super().__init__(config)
        self.register_buffer("mean", torch.zeros(POSE_DIM))

    def prepare(self, train_windows: Any, normalizers: Any = None) -> None:
        """Store the mean over windows and frames of ``train_windows["pose"]`` (a window dict or a store view,
        read in chunks; float64 sums)."""
        _n_train_windows(train_windows, "MeanPose")
        total, count = np.zeros(POSE_DIM), 0
        for chunk in window_chunks(train_windows, "pose"):
            rows = _checked_poses(chunk, "MeanPose").reshape(-1, POSE_DIM)
            total, count = total + rows.sum(axis=0, dtype=np.float64), count + len(rows)
        self.mean.copy_(torch.from_numpy((total / count).astype(np.float32)))

    def forward(self, batch: Batch) -> dict[str, torch.Tensor]:
        """``{"pose": (B, T, 141)}``, every frame = the stored mean."""
        pose = _check_pose(batch, "MeanPose")
        return {"pose": self.mean.to(pose.dtype).expand(pose.shape).clone()}


class RandomClip(_Untrained):
    """Random real clips: each call returns ``B`` clips drawn from a bank of training windows.

    Draws are deterministic: call ``k`` (counted from construction or :meth:`reset`) uses
    ``torch.Generator().manual_seed(seed + k)``. Sequences longer than ``n_frames`` are
    made of consecutive random clips.

    Shapes: ``batch["pose"]`` (B, T, 141) (only its shape and dtype are read) -> ``{"pose": (B, T, 141)}``.

    Examples
    --------
    Five training windows, window ``i`` constant at ``i``; a bank of three of them, ten frames per clip. A
    25-frame request is made of three consecutive clips (frames 0-9, 10-19, 20-24), each one constant bank
    window, and ``reset`` replays the draws.

    >>> import numpy as np, torch
    >>> from beatlite.models import build_model
    >>> model = build_model("random_clip", n_clips=3, n_frames=10)
    >>> train = {"pose": np.arange(5.0).reshape(5, 1, 1) * np.ones((5, 10, 141))}
    >>> model.prepare(train)
    >>> bank = sorted(model.bank[:, 0, 0].tolist())
    >>> pose = model.generate({"pose": torch.zeros(1, 25, 141)})
    >>> pieces = [pose[0, a:b] for a, b in ((0, 10), (10, 20), (20, 25))]
    >>> all(bool((p == p[0, 0]).all()) and p[0, 0].item() in bank for p in pieces)
    True
    >>> model.reset()
    >>> torch.equal(model.generate({"pose": torch.zeros(1, 25, 141)}), pose)
    True
    """

    name = "random_clip"
    representation = "euler141"
    config_class = RandomClipConfig

    def __init__(self, config: RandomClipConfig) -> None:
        super().__init__(config)
        if config.n_clips < 1 or config.n_frames < 1:
            raise ValueError(
                f"RandomClip: n_clips and n_frames must be >= 1, got {config.n_clips}, {config.n_frames}"
            )
        self.register_buffer("bank", torch.zeros(config.n_clips, config.n_frames, POSE_DIM))
        self._calls = 0

    def reset(self) -> None:
        """Restart the sequence of draws."""
        self._calls = 0

    def prepare(self, train_windows: Any, normalizers: Any = None) -> None:
        """Keep ``n_clips`` training windows drawn with ``seed`` (a window dict or a store view: only they are read)."""
        n = _n_train_windows(train_windows, "RandomClip")
        cfg = self.config
        rng = np.random.default_rng(cfg.seed)
        idx = rng.choice(n, size=cfg.n_clips, replace=n < cfg.n_clips)
        pose = _checked_poses(window_rows(train_windows, "pose", idx), "RandomClip")
        if pose.shape[1] < cfg.n_frames:
            raise ValueError(
                f"RandomClip.prepare: windows have {pose.shape[1]} frames < n_frames={cfg.n_frames}"
            )
        self.bank.copy_(torch.from_numpy(pose[:, : cfg.n_frames]))

    def forward(self, batch: Batch) -> dict[str, torch.Tensor]:
        """``{"pose": (B, T, 141)}`` of random bank clips (not depending on any input)."""
        pose = _check_pose(batch, "RandomClip")
        b, t, _ = pose.shape
        gen = torch.Generator().manual_seed(int(self.config.seed) + self._calls)
        self._calls += 1
        n_units = -(-t // self.config.n_frames)
        idx = torch.randint(0, self.config.n_clips, (b, n_units), generator=gen)
        clips = self.bank[idx.reshape(-1)].reshape(b, n_units * self.config.n_frames, POSE_DIM)
        return {"pose": clips[:, :t].to(pose.dtype).clone()}


# ------------------------------------------------------------------------------------ learned
class _Adversarial(GestureModel):
    """Reconstruction + NS-GAN objective shared by the learned baselines."""

    def _build_discriminator(self) -> None:
        cfg = self.config
        if cfg.adversarial:
            self.discriminator = ConvDiscriminator(
                POSE_DIM, hidden=cfg.d_hidden, n_layers=cfg.d_layers, n_frames=cfg.n_frames
            )

    def _losses(self, batch: Batch, out: dict[str, torch.Tensor], epoch: int) -> dict[str, torch.Tensor]:
        cfg = self.config
        rec = huber(out["pose"], batch["pose"])
        adv = rec.new_zeros(())
        if self.adversarial_active(epoch):
            adv = ns_gan_g_loss(self.discriminator(out["pose"]))
        return {"rec": rec, "adv": adv, "total": cfg.rec_weight * rec + cfg.adv_weight * adv}

    def discriminator_losses(self, batch: Batch, out: dict[str, torch.Tensor]) -> dict[str, torch.Tensor]:
        """NS-GAN discriminator loss on real ``batch["pose"]`` vs detached ``out["pose"]``."""
        if self.discriminator is None:
            raise RuntimeError(f"{type(self).__name__} was built with adversarial=False")
        d = ns_gan_d_loss(self.discriminator(batch["pose"]), self.discriminator(out["pose"].detach()))
        return {"d": d, "total": d}


@dataclasses.dataclass
class S2GConfig(AdversarialConfig):
    """Speech2Gesture-style model: ``channels`` wide convolutions over 128-bin log-mel frames."""

    preset: str = "paper"
    n_mels: int = 128
    channels: int = 256
    slope: float = 0.2
    rec_weight: float = 500.0


def _conv_block(a: int, b: int, k: int, stride: int, pad: int, slope: float) -> nn.Sequential:
    return nn.Sequential(
        nn.Conv1d(a, b, k, stride=stride, padding=pad), nn.BatchNorm1d(b), nn.LeakyReLU(slope)
    )


class S2G(_Adversarial):
    """Audio-only convolutional generator in the style of Speech2Gesture.

    ``mel (B, M, 128)`` (dB, ``ref=max``) is mapped to ``mel / 40 + 1``, encoded by two
    ``Conv1d(k3)`` blocks, linearly resampled from M to T frames, then a 1-D U-Net
    (two stride-2 downsamplings, nearest upsampling with additive skips) and a 1x1
    convolution output 141 channels. It ignores the seed pose (as S2G has none).

    Shapes: ``batch["mel"]`` (B, M, 128) dB, ``batch["pose"]`` (B, T, 141) (only T is read)
    -> ``{"pose": (B, T, 141)}``.

    Parameters
    ----------
    config : S2GConfig
        Build one with ``beatlite.models.build_model("s2g", preset="tiny")``.

    Examples
    --------
    A tiny S2G on two fake windows of 70 mel frames: the pose has the batch's T = 34 frames, and any pose
    values give the same output (the audio alone drives it).

    >>> import torch
    >>> from beatlite.models import build_model
    >>> from beatlite.models.testing import fake_batch
    >>> _ = torch.manual_seed(0)
    >>> model = build_model("s2g", preset="tiny").eval()
    >>> batch = fake_batch(2)
    >>> pose = model({"mel": batch["mel"], "pose": batch["pose"]})["pose"]
    >>> tuple(batch["mel"].shape), tuple(pose.shape)
    ((2, 70, 128), (2, 34, 141))
    >>> torch.equal(model({"mel": batch["mel"], "pose": torch.zeros(2, 34, 141)})["pose"], pose)
    True
    """

    name = "s2g"
    representation = "euler141"
    config_class = S2GConfig
    input_keys = ("pose", "mel")

    def __init__(self, config: S2GConfig) -> None:
        super().__init__(config)
        c, s = config.channels, config.slope
        self.audio = nn.Sequential(_conv_block(config.n_mels, c, 3, 1, 1, s), _conv_block(c, c, 3, 1, 1, s))
        self.down0 = _conv_block(c, c, 3, 1, 1, s)
        self.down1 = _conv_block(c, c, 4, 2, 1, s)
        self.down2 = _conv_block(c, c, 4, 2, 1, s)
        self.up1 = _conv_block(c, c, 3, 1, 1, s)
        self.up0 = _conv_block(c, c, 3, 1, 1, s)
        self.out = nn.Conv1d(c, POSE_DIM, 1)
        self._build_discriminator()

    def forward(self, batch: Batch) -> dict[str, torch.Tensor]:
        """``{"pose": (B, T, 141)}`` from ``batch["mel"]`` alone."""
        pose = _check_pose(batch, "S2G")
        check_batch(batch, ("mel",), "S2G")
        mel = batch["mel"]
        if mel.ndim != 3 or mel.shape[-1] != self.config.n_mels:
            raise ValueError(
                f"S2G: batch['mel'] must be (B, M, {self.config.n_mels}), got shape {tuple(mel.shape)}"
            )
        t = pose.shape[1]
        x = self.audio((mel / 40.0 + 1.0).transpose(1, 2))
        x = nn.functional.interpolate(x, size=t, mode="linear", align_corners=False)
        d0 = self.down0(x)
        d1 = self.down1(d0)
        d2 = self.down2(d1)
        u1 = self.up1(nn.functional.interpolate(d2, size=d1.shape[-1], mode="nearest") + d1)
        u0 = self.up0(nn.functional.interpolate(u1, size=t, mode="nearest") + d0)
        return {"pose": self.out(u0).transpose(1, 2)}

    def losses(self, batch: Batch, out: dict[str, torch.Tensor], *, epoch: int) -> dict[str, torch.Tensor]:
        """``{"rec", "adv", "total"}``."""
        return self._losses(batch, out, epoch)


@dataclasses.dataclass
class TrimodalConfig(TextConfig, AdversarialConfig):
    """Trimodal / MultiContext-style hyper-parameters (defaults = ``paper``: docs/reference_code.md#trimodal, hidden 300, 4 layers)."""

    preset: str = "paper"
    audio_channels: tuple[int, ...] = (16, 32, 64, 32)
    n_speakers: int = N_SPEAKERS
    speaker_z: int = 16
    hidden: int = 300
    n_layers: int = 4
    dropout: float = 0.3
    slope: float = 0.1
    rec_weight: float = 500.0
    kld_weight: float = 0.1

    def __post_init__(self) -> None:
        self.audio_channels = tuple(int(c) for c in self.audio_channels)


class Trimodal(_Adversarial):
    """Text + audio + speaker GRU in the style of Trimodal / MultiContext.

    ``x = cat[pre_seq (T, 142), text (T, text_features), audio (T, audio_channels[-1]), z (T, speaker_z)]``
    -> biGRU (directions summed) -> ``Linear(h, h/2) -> LReLU(0.1) -> Linear(h/2, 141)``.
    The speaker style ``z`` is sampled with the reparameterisation trick while training
    and is its mean ``mu`` in eval mode (deterministic generation).

    Shapes: ``batch["pose"]`` (B, T, 141) (the first ``n_pre`` frames seed it), ``batch["audio"]`` (B, S)
    16 kHz, ``batch["word"]`` (B, T) int64, ``batch["speaker"]`` (B,) int64 -> ``{"pose": (B, T, 141),
    "z_mu": (B, Z), "z_logvar": (B, Z)}`` with Z = ``speaker_z``.

    Parameters
    ----------
    config : TrimodalConfig
        Build one with ``beatlite.models.build_model("trimodal", preset="tiny")``.

    Examples
    --------
    A tiny Trimodal on two fake windows: the pose and the speaker style's Gaussian (Z = 16); the ``kld`` loss
    term is the closed-form KL of that Gaussian from N(0, I), averaged over its elements.

    >>> import torch
    >>> from beatlite.models import build_model
    >>> from beatlite.models.layers import kl_standard_normal
    >>> from beatlite.models.testing import fake_batch
    >>> _ = torch.manual_seed(0)
    >>> model = build_model("trimodal", preset="tiny")
    >>> batch = fake_batch(2, vocab_size=1000)
    >>> out = model(batch)
    >>> tuple(out["pose"].shape), tuple(out["z_mu"].shape)
    ((2, 34, 141), (2, 16))
    >>> losses = model.losses(batch, out, epoch=0)
    >>> bool(torch.isclose(losses["kld"], kl_standard_normal(out["z_mu"], out["z_logvar"])))
    True
    >>> sorted(losses)  # the adversarial term is 0 before epoch no_adv_epochs
    ['adv', 'kld', 'rec', 'total']
    """

    name = "trimodal"
    representation = "euler141"
    config_class = TrimodalConfig
    input_keys = ("pose", "audio", "word", "speaker")

    def __init__(self, config: TrimodalConfig) -> None:
        super().__init__(config)
        cfg = config
        self.text_encoder = TextEncoderTCN(
            cfg.vocab_size, cfg.word_dim, cfg.text_hidden, cfg.text_layers, cfg.text_features, cfg.dropout
        )
        self.audio_encoder = PlainWavEncoder(cfg.audio_channels)
        self.speaker_embedding = nn.Sequential(
            nn.Embedding(cfg.n_speakers, cfg.speaker_z), nn.Linear(cfg.speaker_z, cfg.speaker_z)
        )
        self.speaker_mu = nn.Linear(cfg.speaker_z, cfg.speaker_z)
        self.speaker_logvar = nn.Linear(cfg.speaker_z, cfg.speaker_z)
        in_size = POSE_DIM + 1 + cfg.text_features + cfg.audio_channels[-1] + cfg.speaker_z
        self.gru = nn.GRU(
            in_size,
            cfg.hidden,
            num_layers=cfg.n_layers,
            batch_first=True,
            bidirectional=True,
            dropout=cfg.dropout if cfg.n_layers > 1 else 0.0,
        )
        self.head = nn.Sequential(
            nn.Linear(cfg.hidden, cfg.hidden // 2),
            nn.LeakyReLU(cfg.slope),
            nn.Linear(cfg.hidden // 2, POSE_DIM),
        )
        self._build_discriminator()

    def word_embeddings(self) -> list[nn.Embedding]:
        """The text encoder's embedding."""
        return [self.text_encoder.embedding]

    def forward(self, batch: Batch) -> dict[str, torch.Tensor]:
        """``{"pose": (B,T,141), "z_mu", "z_logvar"}``."""
        pose = _check_pose(batch, "Trimodal")
        check_batch(batch, self.input_keys, "Trimodal")
        speaker = batch["speaker"]
        if speaker.ndim != 1:
            raise ValueError(f"Trimodal: batch['speaker'] must be (B,), got shape {tuple(speaker.shape)}")
        check_ids(speaker, self.config.n_speakers, "Trimodal: batch['speaker'] ids")
        b, t, _ = pose.shape
        text = match_length(self.text_encoder(batch["word"]), t)
        audio = match_length(self.audio_encoder(batch["audio"]), t)
        h = self.speaker_embedding(speaker)
        mu, logvar = self.speaker_mu(h), self.speaker_logvar(h)
        z = reparameterize(mu, logvar, torch.randn_like(mu)) if self.training else mu
        x = torch.cat([seed_input(pose, self.n_pre), text, audio, z.unsqueeze(1).expand(b, t, -1)], -1)
        seq, _ = self.gru(x)
        return {"pose": self.head(sum_directions(seq, self.config.hidden)), "z_mu": mu, "z_logvar": logvar}

    def losses(self, batch: Batch, out: dict[str, torch.Tensor], *, epoch: int) -> dict[str, torch.Tensor]:
        """``{"rec", "adv", "kld", "total"}``; KLD = ``-0.5 mean(1 + logvar - mu^2 - exp(logvar))``."""
        parts = self._losses(batch, out, epoch)
        mu, logvar = out["z_mu"], out["z_logvar"]
        kld = kl_standard_normal(mu, logvar)
        parts["kld"] = kld
        parts["total"] = parts["total"] + self.config.kld_weight * kld
        return parts


PRESETS: dict[str, dict[str, Any]] = {"tiny": {}, "paper": {}}
"""Presets of the untrained rows (no options)."""

S2G_PRESETS: dict[str, dict[str, Any]] = {
    "paper": {},
    "tiny": {"channels": 48, "d_hidden": 32, "d_layers": 1},
}
TRIMODAL_PRESETS: dict[str, dict[str, Any]] = {
    "paper": {},
    "tiny": {
        "vocab_size": 1000,
        "word_dim": 64,
        "text_hidden": 48,
        "text_layers": 2,
        "hidden": 64,
        "n_layers": 1,
        "dropout": 0.1,
        "d_hidden": 32,
        "d_layers": 1,
    },
}

S2G.presets = S2G_PRESETS
Trimodal.presets = TRIMODAL_PRESETS
