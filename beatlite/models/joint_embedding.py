"""Joint Embedding (speech and pose in one latent space): Yoon et al. 2020's TED adaptation of Language2Pose.

Ahuja, Morency: "Language2Pose: natural language grounded pose forecasting", 3DV 2019 (its Joint
Language-to-Pose model, JL2P). It is the "Joint Embedding" row of HA2G Table 1 (HA2G Sec. 4.2: "maps
the text and motion to the same embedding space and creates motion from description text"), whose
numbers come from Yoon et al. 2020's adaptation in ``ai4r/Gesture-Generation-from-Trimodal-Context``
(``scripts/model/embedding_net.py``, ``EmbeddingNet`` in mode ``"random"``; ``config/joint_embed.yml``;
``scripts/train_eval/train_joint_embed.py``). The ``paper`` preset has that code's layers, widths,
sampling and loss (docs/reference_code.md#joint-embedding).

Data flow (T = 34 frames; sizes of the ``paper`` preset)::

    context: word (B,T) -> TextEncoderTCN(200 x 2 levels) -> (B,T,32) ┐
             audio (B,36266) -> PlainWavEncoder (16 32 64 32) -> (B,T,32) ┴ cat -> GRU(256, 2 layers)
             -> last state -> Linear(128) -> BN -> ReLU -> Linear(32) -> mu, logvar (Linear 32 each)
             -> z_context ~ N(mu, exp(logvar))                  (sampled, in training and at inference)
    pose:    pose (B,T,141) -> [Conv1d(k3) -> BN -> LReLU(0.2)] 141->32, 32->64, [k4 stride 2] 64->64
             -> Conv1d(64, 32, k3) -> flatten (12 x 32 = 384) -> Linear(256) -> BN -> LReLU(1)
             -> Linear(128) -> BN -> LReLU(1) -> Linear(32) -> mu (Linear 32)  = z_pose (not sampled)
    decoder(z, seed): cat[Linear(4 x 141 -> 32) -> BN -> ReLU -> Linear(32), z] repeated over T
             -> biGRU(300, 4 layers, dropout 0.3), directions summed -> Linear(150) -> LReLU(1) -> Linear(141)
    "pose" = decoder(z_context, seed)        "pose_recon" = decoder(z_pose, seed)

The loss is the L1 reconstruction of the motion from either embedding: the decoder can only succeed
if the speech embedding lands where the pose embedding of the same motion does. Inference decodes
the (sampled) speech embedding.

Differences from the reference code at the ``paper`` preset (same layers; parameter count equal, the
pose encoder's log-variance head included but frozen, below):

- Loss: the reference draws per training step which of the two embeddings to decode (a fair coin) and
  takes the L1 of that one; beatlite takes ``rec_weight`` (0.5) times each of the two L1s every step,
  the coin's expected loss (every parameter gets a gradient at every step), and the batch mean
  where the reference sums over the batch (Adam is almost invariant to the scale).
- The pose encoder's log-variance head is built (so the parameter count is the reference's) but
  frozen: the reference's joint-embedding training encodes poses with ``z = mu`` and never uses it.
- ``LReLU(1)``: the reference writes ``nn.LeakyReLU(True)``, a negative slope of ``True`` = 1, so these
  activations are the identity; kept (``slope``).
- Inference draws the speech embedding from ``torch.Generator().manual_seed(seed + k)`` on the ``k``-th
  eval call since construction or :meth:`JointEmbedding.reset` (the reference draws from the global
  random state); ``eval_z="mean"`` (an extra option) decodes ``mu``.
- The text is the window's per-frame word ids (a word repeated over the frames it spans, PAD = 0 in
  silences, BEAT's rule), as every beatlite model reads it; the reference's padded word sequence puts each word
  only at the frame where it starts (docs/reference_code.md#textgrid, the "onset" rule).
- The output is ``euler141`` (z-scored Euler channels, like CaMN, S2G and Trimodal), not TED's 27
  direction-vector channels; the optimiser settings are the recipe's (reference: Adam, lr 5e-4,
  batch 128, 100 epochs).

Differences from the paper (Language2Pose): the reference above is followed, so the context encoder
reads speech text *and audio* (Language2Pose: a sentence describing the motion), its embedding is
sampled, the pose encoder is convolutional and there is no curriculum over sequence lengths. The
``tiny`` preset narrows the text TCN, the context GRU and MLP, the pose MLP and the decoder GRU
(:data:`PRESETS`), and nothing else.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import torch
from torch import nn

from beatlite.constants import WINDOW_LENGTH
from beatlite.models.base import N_PRE, Batch, GestureModel, TextConfig, check_batch
from beatlite.models.layers import (
    PlainWavEncoder,
    TextEncoderTCN,
    match_length,
    reparameterize,
    sum_directions,
)

POSE_DIM = 141
EVAL_Z = ("sample", "mean")


@dataclasses.dataclass
class JointEmbeddingConfig(TextConfig):
    """Joint Embedding hyper-parameters (defaults = ``paper``: the sizes of Yoon et al. 2020's code).

    Attributes
    ----------
    vocab_size, word_dim, text_hidden, text_layers, text_features : int
        :class:`~beatlite.models.layers.TextEncoderTCN` sizes (reference: ``hidden_size`` 200 and
        ``n_layers`` 2, the defaults of its ``parse_args``, which ``joint_embed.yml`` does not set).
    text_dropout : float
        Dropout inside the text TCN (reference 0.3).
    audio_channels : tuple of 4 int
        :class:`~beatlite.models.layers.PlainWavEncoder` widths.
    context_hidden, context_layers : int
        Width and depth of the context GRU (reference 256, 2).
    context_mlp : int
        Hidden width of the context encoder's output MLP (128).
    pose_mlp : tuple of 2 int
        Hidden widths of the pose encoder's output MLP (256, 128).
    embed_dim : int
        Size of the joint embedding and of the seed-pose feature (32).
    hidden, dec_layers : int
        Width and depth of the bidirectional decoder GRU (300, 4).
    dropout : float
        Dropout between decoder GRU layers (0.3).
    slope : float
        Negative slope of the pose encoder's MLP and the output head (reference ``LeakyReLU(True)`` = 1).
    rec_weight : float
        Weight of each of the two L1 reconstructions (0.5: the reference's coin in expectation).
    n_frames : int
        Window length T; the pose encoder's flattened size depends on it.
    eval_z : str
        ``"sample"`` (the reference) or ``"mean"``: the speech embedding at inference.
    seed : int
        Base seed of the inference draws.
    """

    preset: str = "paper"
    text_hidden: int = 200
    text_layers: int = 2
    text_dropout: float = 0.3
    audio_channels: tuple[int, ...] = (16, 32, 64, 32)
    context_hidden: int = 256
    context_layers: int = 2
    context_mlp: int = 128
    pose_mlp: tuple[int, ...] = (256, 128)
    embed_dim: int = 32
    hidden: int = 300
    dec_layers: int = 4
    dropout: float = 0.3
    slope: float = 1.0
    rec_weight: float = 0.5
    n_frames: int = WINDOW_LENGTH
    eval_z: str = "sample"
    seed: int = 0

    def __post_init__(self) -> None:
        self.audio_channels = tuple(int(c) for c in self.audio_channels)
        self.pose_mlp = tuple(int(c) for c in self.pose_mlp)
        if len(self.pose_mlp) != 2:
            raise ValueError(f"JointEmbeddingConfig: pose_mlp must have 2 widths, got {self.pose_mlp}")
        if self.eval_z not in EVAL_Z:
            raise ValueError(f"JointEmbeddingConfig: eval_z must be one of {EVAL_Z}, got {self.eval_z!r}")
        if conv_frames(self.n_frames) < 1:
            raise ValueError(f"JointEmbeddingConfig: n_frames must be >= 13, got {self.n_frames}")


def conv_frames(t: int) -> int:
    """Frames left after the pose encoder's convolutions (k3, k3, k4 stride 2, k3; no padding).

    Examples
    --------
    >>> conv_frames(34)  # 34 -> 32 -> 30 -> 14 -> 12
    12
    """
    return ((t - 4) - 4) // 2 + 1 - 2


def _conv_bn(c_in: int, c_out: int, kernel: int, stride: int) -> list[nn.Module]:
    return [nn.Conv1d(c_in, c_out, kernel, stride=stride), nn.BatchNorm1d(c_out), nn.LeakyReLU(0.2)]


class JointEmbedding(GestureModel):
    """Speech and pose encoders into one embedding, one seed-conditioned decoder (module docstring).

    Shapes: ``batch["word"]`` (B, T) int64, ``batch["audio"]`` (B, S) float, ``batch["pose"]``
    (B, T, 141) -> ``{"pose", "pose_recon"}`` (B, T, 141), ``{"z_context", "context_mu",
    "context_logvar", "z_pose"}`` (B, embed_dim). ``"pose"`` reads only the words, the audio and the
    first ``n_pre`` pose frames.

    Parameters
    ----------
    config : JointEmbeddingConfig
        Build one with ``beatlite.models.build_model("joint_embedding", preset="tiny")``.

    Examples
    --------
    A tiny model on two fake windows: both decodings have the pose's shape, both embeddings ``embed_dim``
    channels; with ``eval_z="mean"`` inference uses the speech embedding's mean, and the loss is
    ``rec_weight`` (0.5) times the sum of the two L1 reconstructions.

    >>> import torch
    >>> from beatlite.models import build_model
    >>> from beatlite.models.testing import fake_batch
    >>> _ = torch.manual_seed(0)
    >>> model = build_model("joint_embedding", preset="tiny", eval_z="mean").eval()
    >>> batch = {k: v for k, v in fake_batch(2, vocab_size=1000).items() if k in ("pose", "word", "audio")}
    >>> out = model(batch)
    >>> tuple(out["pose"].shape), tuple(out["pose_recon"].shape), tuple(out["z_context"].shape)
    ((2, 34, 141), (2, 34, 141), (2, 32))
    >>> torch.equal(out["z_context"], out["context_mu"])
    True
    >>> losses = model.losses(batch, out, epoch=0)
    >>> bool(torch.isclose(losses["total"], 0.5 * (losses["speech_rec"] + losses["pose_rec"])))
    True
    """

    name = "joint_embedding"
    representation = "euler141"
    config_class = JointEmbeddingConfig
    input_keys = ("pose", "word", "audio")

    def __init__(self, config: JointEmbeddingConfig) -> None:
        super().__init__(config)
        cfg = config
        e = cfg.embed_dim
        self.text_encoder = TextEncoderTCN(
            cfg.vocab_size,
            cfg.word_dim,
            cfg.text_hidden,
            cfg.text_layers,
            cfg.text_features,
            cfg.text_dropout,
        )
        self.audio_encoder = PlainWavEncoder(cfg.audio_channels)
        self.context_gru = nn.GRU(
            cfg.text_features + cfg.audio_channels[-1],
            cfg.context_hidden,
            cfg.context_layers,
            batch_first=True,
        )
        self.context_out = nn.Sequential(
            nn.Linear(cfg.context_hidden, cfg.context_mlp), nn.BatchNorm1d(cfg.context_mlp), nn.ReLU(),
            nn.Linear(cfg.context_mlp, e),
        )  # fmt: skip
        self.context_mu, self.context_logvar = nn.Linear(e, e), nn.Linear(e, e)
        self.pose_conv = nn.Sequential(
            *_conv_bn(POSE_DIM, 32, 3, 1),
            *_conv_bn(32, 64, 3, 1),
            *_conv_bn(64, 64, 4, 2),
            nn.Conv1d(64, 32, 3),
        )
        h1, h2 = cfg.pose_mlp
        self.pose_out = nn.Sequential(
            nn.Linear(32 * conv_frames(cfg.n_frames), h1), nn.BatchNorm1d(h1), nn.LeakyReLU(cfg.slope),
            nn.Linear(h1, h2), nn.BatchNorm1d(h2), nn.LeakyReLU(cfg.slope),
            nn.Linear(h2, e),
        )  # fmt: skip
        self.pose_mu, self.pose_logvar = nn.Linear(e, e), nn.Linear(e, e)
        self.pose_logvar.requires_grad_(False)  # never used by the reference's joint-embedding training
        self.seed_net = nn.Sequential(
            nn.Linear(N_PRE * POSE_DIM, e), nn.BatchNorm1d(e), nn.ReLU(), nn.Linear(e, e)
        )
        self.decoder = nn.GRU(
            2 * e,
            cfg.hidden,
            num_layers=cfg.dec_layers,
            batch_first=True,
            bidirectional=True,
            dropout=cfg.dropout if cfg.dec_layers > 1 else 0.0,
        )
        self.head = nn.Sequential(
            nn.Linear(cfg.hidden, cfg.hidden // 2),
            nn.LeakyReLU(cfg.slope),
            nn.Linear(cfg.hidden // 2, POSE_DIM),
        )
        self._calls = 0

    def reset(self) -> None:
        """Restart the sequence of inference draws."""
        self._calls = 0

    def word_embeddings(self) -> list[nn.Embedding]:
        """The text encoder's embedding."""
        return [self.text_encoder.embedding]

    def encode_context(self, words: torch.Tensor, audio: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """(B, T) word ids and (B, S) audio -> mu, logvar (B, embed_dim) of the speech embedding."""
        text = self.text_encoder(words)
        wav = match_length(self.audio_encoder(audio), text.shape[1])
        seq, _ = self.context_gru(torch.cat([wav, text], dim=-1))
        h = self.context_out(seq[:, -1])
        return self.context_mu(h), self.context_logvar(h)

    def embed_pose(self, pose: torch.Tensor) -> torch.Tensor:
        """(B, T, 141) -> (B, embed_dim) (the mean; the reference does not sample it here)."""
        h = self.pose_conv(pose.transpose(1, 2)).flatten(1)
        return self.pose_mu(self.pose_out(h))

    def decode(self, z: torch.Tensor, pose: torch.Tensor) -> torch.Tensor:
        """Embedding (B, embed_dim) and the seed frames of ``pose`` (B, T, 141) -> (B, T, 141)."""
        b, t, _ = pose.shape
        seed = self.seed_net(pose[:, : self.n_pre].reshape(b, -1))
        x = torch.cat([seed, z], dim=-1).unsqueeze(1).expand(b, t, -1)
        seq, _ = self.decoder(x)
        return self.head(sum_directions(seq, self.config.hidden))

    def forward(self, batch: Batch) -> dict[str, torch.Tensor]:
        """``{"pose", "pose_recon", "z_context", "context_mu", "context_logvar", "z_pose"}`` (class docstring)."""
        check_batch(batch, self.input_keys, "JointEmbedding")
        pose, words = batch["pose"], batch["word"]
        t = self.config.n_frames
        if pose.ndim != 3 or pose.shape[-1] != POSE_DIM or pose.shape[1] != t:
            raise ValueError(
                f"JointEmbedding: batch['pose'] must be (B, {t}, {POSE_DIM}), got {tuple(pose.shape)}"
            )
        if words.shape != pose.shape[:2]:
            raise ValueError(
                f"JointEmbedding: batch['word'] must be (B, T) = {tuple(pose.shape[:2])}, got {tuple(words.shape)}"
            )
        mu, logvar = self.encode_context(words, batch["audio"])
        if self.training:
            noise = torch.randn_like(mu)
        elif self.config.eval_z == "mean":
            noise = torch.zeros_like(mu)
        else:
            gen = torch.Generator().manual_seed(int(self.config.seed) + self._calls)
            self._calls += 1
            noise = torch.randn(mu.shape, generator=gen).to(mu)
        z_context = reparameterize(mu, logvar, noise)
        z_pose = self.embed_pose(pose)
        return {
            "pose": self.decode(z_context, pose),
            "pose_recon": self.decode(z_pose, pose),
            "z_context": z_context,
            "context_mu": mu,
            "context_logvar": logvar,
            "z_pose": z_pose,
        }

    def losses(self, batch: Batch, out: dict[str, torch.Tensor], *, epoch: int) -> dict[str, torch.Tensor]:
        """``{"speech_rec", "pose_rec", "total"}``: L1 of each decoding against ``batch["pose"]``."""
        l1 = nn.functional.l1_loss
        speech_rec, pose_rec = l1(out["pose"], batch["pose"]), l1(out["pose_recon"], batch["pose"])
        return {
            "speech_rec": speech_rec,
            "pose_rec": pose_rec,
            "total": self.config.rec_weight * (speech_rec + pose_rec),
        }


PRESETS: dict[str, dict[str, Any]] = {
    "paper": {},
    "tiny": {
        "vocab_size": 1000,
        "word_dim": 64,
        "text_hidden": 48,
        "context_hidden": 64,
        "context_layers": 1,
        "context_mlp": 64,
        "pose_mlp": (64, 64),
        "hidden": 64,
        "dec_layers": 1,
        "dropout": 0.1,
        "text_dropout": 0.1,
    },
}
"""``paper``: the reference's sizes (text TCN 200 x 2, context GRU 256 x 2, decoder 300 x 4); ``tiny``: text
TCN 48 x 2 over 64-d words, context GRU 64 x 1, pose MLP 64-64, decoder GRU 64 x 1, dropout 0.1."""
