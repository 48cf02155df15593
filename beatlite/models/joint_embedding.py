"""Joint Embedding (text and pose in one latent space) in the style of Language2Pose, runnable on a CPU.

Ahuja, Morency: "Language2Pose: natural language grounded pose forecasting", 3DV 2019 (its Joint
Language-to-Pose model, JL2P). It is the "Joint Embedding" row of HA2G Table 1 (HA2G
Sec. 4.2: "maps the text and motion to the same embedding space and creates motion from
description text").

Data flow (T = 34 frames; sizes of the ``paper`` preset)::

    word (B,T) -> TextEncoderTCN -> (B,T,32) -> GRU(300) -> last state -> Linear -> z_text (B,32)
    pose (B,T,141) ------------------------------> GRU(300) -> last state -> Linear -> z_pose (B,32)
    decoder(z, seed) : cat[z, Linear(seed frames (n_pre * 141) -> 32)] repeated over T
                       -> biGRU(300, 4 layers), directions summed -> Linear -> LReLU -> Linear -> (B,T,141)
    "pose" = decoder(z_text, seed)        "pose_recon" = decoder(z_pose, seed)

Kept from the paper: a sentence encoder and a pose encoder that map into one embedding space, and a
single pose decoder conditioned on the initial poses that must produce the motion from either
embedding; the training loss is the sum of both reconstructions, so the decoder can only succeed
if the text embedding lands where the pose embedding of the same motion does. Inference decodes
the text embedding.

Simplified or changed:

- The text is the window's per-frame word ids (a word repeated over the frames it spans, PAD = 0
  in silences), encoded by the TCN text encoder beatlite's Trimodal uses
  (:class:`~beatlite.models.layers.TextEncoderTCN`) and summarised by a GRU, in place of the
  paper's recurrent sentence encoder over a motion description.
- Both reconstructions are trained at every step (L1, ``rec_weight`` each), where Yoon et al.
  2020's released adaptation picks one of the two at random per step; no curriculum over sequence
  lengths (Language2Pose's curriculum; windows here are always 34 frames).
- Yoon et al. 2020's TED adaptation of this baseline, whose numbers HA2G Table 1 quotes, also
  feeds audio to the context encoder; this model reads text only, as Language2Pose.
- The output is ``euler141`` (z-scored Euler channels, like CaMN, S2G and Trimodal), not joint
  positions.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import torch
from torch import nn

from beatlite.models.base import N_PRE, Batch, GestureModel, TextConfig, check_batch
from beatlite.models.layers import TextEncoderTCN, mlp, sum_directions

POSE_DIM = 141


@dataclasses.dataclass
class JointEmbeddingConfig(TextConfig):
    """Joint Embedding hyper-parameters (defaults = ``paper``: the sizes of Yoon et al. 2020's baseline).

    Attributes
    ----------
    vocab_size, word_dim, text_hidden, text_layers, text_features : int
        :class:`~beatlite.models.layers.TextEncoderTCN` sizes (:class:`~beatlite.models.base.TextConfig`).
    hidden : int
        Width of the two encoder GRUs and of the decoder GRU.
    dec_layers : int
        Layers of the bidirectional decoder GRU.
    embed_dim : int
        Size of the joint embedding (and of the seed-pose feature).
    dropout : float
        Dropout of the text TCN and between decoder GRU layers.
    slope : float
        LeakyReLU slope of the output head.
    rec_weight : float
        Weight of each L1 reconstruction.
    """

    preset: str = "paper"
    hidden: int = 300
    dec_layers: int = 4
    embed_dim: int = 32
    dropout: float = 0.3
    slope: float = 0.1
    rec_weight: float = 1.0


class JointEmbedding(GestureModel):
    """Text and pose encoders into one embedding, one seed-conditioned decoder (module docstring).

    Shapes: ``batch["word"]`` (B, T) int64, ``batch["pose"]`` (B, T, 141) ->
    ``{"pose", "pose_recon"}`` (B, T, 141), ``{"z_text", "z_pose"}`` (B, embed_dim).
    ``"pose"`` reads only the words and the first ``n_pre`` pose frames.
    """

    name = "joint_embedding"
    representation = "euler141"
    config_class = JointEmbeddingConfig
    input_keys = ("pose", "word")

    def __init__(self, config: JointEmbeddingConfig) -> None:
        super().__init__(config)
        cfg = config
        self.text_encoder = TextEncoderTCN(
            cfg.vocab_size, cfg.word_dim, cfg.text_hidden, cfg.text_layers, cfg.text_features, cfg.dropout
        )
        self.text_gru = nn.GRU(cfg.text_features, cfg.hidden, batch_first=True)
        self.text_out = nn.Linear(cfg.hidden, cfg.embed_dim)
        self.pose_gru = nn.GRU(POSE_DIM, cfg.hidden, batch_first=True)
        self.pose_out = nn.Linear(cfg.hidden, cfg.embed_dim)
        self.seed_net = nn.Linear(N_PRE * POSE_DIM, cfg.embed_dim)
        self.decoder = nn.GRU(
            2 * cfg.embed_dim,
            cfg.hidden,
            num_layers=cfg.dec_layers,
            batch_first=True,
            bidirectional=True,
            dropout=cfg.dropout if cfg.dec_layers > 1 else 0.0,
        )
        self.head = mlp((cfg.hidden, cfg.hidden // 2, POSE_DIM), cfg.slope, last_act=False)

    def word_embeddings(self) -> list[nn.Embedding]:
        """The text encoder's embedding."""
        return [self.text_encoder.embedding]

    def embed_text(self, words: torch.Tensor) -> torch.Tensor:
        """(B, T) word ids -> (B, embed_dim)."""
        seq, _ = self.text_gru(self.text_encoder(words))
        return self.text_out(seq[:, -1])

    def embed_pose(self, pose: torch.Tensor) -> torch.Tensor:
        """(B, T, 141) -> (B, embed_dim)."""
        seq, _ = self.pose_gru(pose)
        return self.pose_out(seq[:, -1])

    def decode(self, z: torch.Tensor, pose: torch.Tensor) -> torch.Tensor:
        """Embedding (B, embed_dim) and the seed frames of ``pose`` (B, T, 141) -> (B, T, 141)."""
        b, t, _ = pose.shape
        seed = self.seed_net(pose[:, : self.n_pre].reshape(b, -1))
        x = torch.cat([z, seed], dim=-1).unsqueeze(1).expand(b, t, -1)
        seq, _ = self.decoder(x)
        return self.head(sum_directions(seq, self.config.hidden))

    def forward(self, batch: Batch) -> dict[str, torch.Tensor]:
        """``{"pose", "pose_recon", "z_text", "z_pose"}`` (class docstring)."""
        check_batch(batch, self.input_keys, "JointEmbedding")
        pose, words = batch["pose"], batch["word"]
        if pose.ndim != 3 or pose.shape[-1] != POSE_DIM or pose.shape[1] < self.n_pre:
            raise ValueError(
                f"JointEmbedding: batch['pose'] must be (B, T>={self.n_pre}, {POSE_DIM}), got {tuple(pose.shape)}"
            )
        if words.shape != pose.shape[:2]:
            raise ValueError(
                f"JointEmbedding: batch['word'] must be (B, T) = {tuple(pose.shape[:2])}, got {tuple(words.shape)}"
            )
        z_text, z_pose = self.embed_text(words), self.embed_pose(pose)
        return {
            "pose": self.decode(z_text, pose),
            "pose_recon": self.decode(z_pose, pose),
            "z_text": z_text,
            "z_pose": z_pose,
        }

    def losses(self, batch: Batch, out: dict[str, torch.Tensor], *, epoch: int) -> dict[str, torch.Tensor]:
        """``{"text_rec", "pose_rec", "total"}``: L1 of each decoding against ``batch["pose"]``."""
        l1 = nn.functional.l1_loss
        text_rec, pose_rec = l1(out["pose"], batch["pose"]), l1(out["pose_recon"], batch["pose"])
        return {
            "text_rec": text_rec,
            "pose_rec": pose_rec,
            "total": self.config.rec_weight * (text_rec + pose_rec),
        }


PRESETS: dict[str, dict[str, Any]] = {
    "paper": {},
    "tiny": {
        "vocab_size": 1000,
        "word_dim": 64,
        "text_hidden": 48,
        "text_layers": 2,
        "hidden": 64,
        "dec_layers": 1,
        "dropout": 0.1,
    },
}
"""``paper``: hidden 300, 4 decoder layers; ``tiny``: the text sizes of ``trimodal_tiny``, hidden 64, 1 layer."""
