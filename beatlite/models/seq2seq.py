"""Attention Seq2Seq (text -> gesture) in the style of Yoon et al. 2019, runnable on a CPU.

Yoon, Ko, Jang, Lee, Kim, Lee: "Robots learn social skills: end-to-end learning of co-speech
gesture generation for humanoid robots", ICRA 2019 (its method section: a speech-text encoder and a
gesture decoder with attention). It is the "Seq2Seq" row of BEAT Table 4 (BEAT Sec. 6.3) and the
"Attention Seq2Seq" row of HA2G Table 1 (HA2G Sec. 4.2: "generates gestures from speech text by
attention mechanism").

Data flow for a window batch (T = 34 frames; sizes of the ``paper`` preset)::

    word (B,T) -> Embedding(300) -> biGRU(200, 2 layers), directions summed -> enc (B,T,200)
    decoder state h_0 = the encoder's last states (directions summed per layer)
    out[0] = pose[0]                                              (the first seed frame)
    step t = 1..T-1:  a_t = softmax_s v . tanh(W [h_{t-1}; enc_s])     (Bahdanau attention)
                      c_t = sum_s a_t[s] enc_s
                      x_t = ReLU(BN(Linear(cat[y_{t-1}, c_t])))    -> GRU(200, 2 layers) -> Linear -> out[t]
                      y_t = pose[t] for t < n_pre (the seed), else out[t]   (free running)

Kept from the paper: a bidirectional GRU encoder over words, a GRU decoder with Bahdanau attention
over the encoder outputs that emits one pose per step from its previous pose, and seed poses. The
loss is the one of the authors' released implementation of this baseline (Yoon et al. 2020's TED
code, weights 250 / 0.1 / 25): ``rec_weight * MSE + continuity_weight * mean |out[t] - out[t-1]| +
variance_weight * (-mean_{b,d} ||out[b, :, d]||_2)``, a smoothness term and a motion-variance
reward that counters the mean pose.

Simplified or changed:

- The encoder reads the per-frame word ids of the window (a word is repeated over the frames it
  spans, PAD = 0 in silences), not the utterance's word list: the frame-aligned input every
  beatlite model gets. There is no audio input (the paper's model reads text only).
- The output is the 141 z-scored Euler channels of ``spine_neck_141`` (``euler141``, like CaMN,
  S2G and Trimodal, so BEAT Table 4's rows share one representation), not the paper's
  10-dimensional PCA of 2-D upper-body keypoints.
- The decoder starts from the sum of each encoder layer's two directions (the paper: the last
  encoder state); gradient-norm clipping is the harness's (:class:`beatlite.train.TrainConfig`).
- Training always runs free (the decoder feeds back its own output after the seed), so
  training and :meth:`~beatlite.models.base.GestureModel.generate` see the same inputs.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import torch
from torch import nn

from beatlite.models.base import Batch, GestureModel, ModelConfig, check_batch
from beatlite.models.layers import check_ids, sum_directions

POSE_DIM = 141


@dataclasses.dataclass
class Seq2SeqConfig(ModelConfig):
    """Attention Seq2Seq hyper-parameters (defaults = ``paper``: hidden 200, 2 layers, dropout 0.1).

    Attributes
    ----------
    vocab_size, word_dim : int
        Word embedding table (id 0 = PAD); load pretrained vectors with ``set_word_vectors``.
    hidden, n_layers, dropout : int, int, float
        Width and depth of the encoder and decoder GRUs, dropout between GRU layers.
    rec_weight, continuity_weight, variance_weight : float
        Weights of the MSE, continuity and motion-variance terms of :meth:`Seq2Seq.losses`.
    """

    preset: str = "paper"
    vocab_size: int = 5793
    word_dim: int = 300
    hidden: int = 200
    n_layers: int = 2
    dropout: float = 0.1
    rec_weight: float = 250.0
    continuity_weight: float = 0.1
    variance_weight: float = 25.0


class BahdanauAttention(nn.Module):
    """Additive attention ``a[s] = softmax_s v . tanh(W_h h + W_e enc[s])``.

    Shapes
    ------
    ``keys(enc)``: (B, S, H) -> (B, S, H) (``W_e enc``, computed once per sequence);
    ``forward(h, enc, keys)``: h (B, H), enc (B, S, H) -> context (B, H), weights (B, S).

    Examples
    --------
    With ``v`` zeroed every energy is 0: uniform weights ``1 / S`` and the context is the mean of ``enc``.

    >>> import torch
    >>> from beatlite.models.seq2seq import BahdanauAttention
    >>> _ = torch.manual_seed(0)
    >>> attention = BahdanauAttention(4)
    >>> _ = torch.nn.init.zeros_(attention.v.weight)
    >>> enc = torch.randn(2, 5, 4)
    >>> context, weights = attention(torch.randn(2, 4), enc, attention.keys(enc))
    >>> bool(torch.allclose(weights, torch.full((2, 5), 1 / 5))), bool(torch.allclose(context, enc.mean(1)))
    (True, True)
    """

    def __init__(self, hidden: int) -> None:
        super().__init__()
        self.query = nn.Linear(hidden, hidden, bias=False)
        self.key = nn.Linear(hidden, hidden)
        self.v = nn.Linear(hidden, 1, bias=False)

    def keys(self, enc: torch.Tensor) -> torch.Tensor:
        return self.key(enc)

    def forward(
        self, h: torch.Tensor, enc: torch.Tensor, keys: torch.Tensor
    ) -> tuple[torch.Tensor, torch.Tensor]:
        energy = self.v(torch.tanh(keys + self.query(h).unsqueeze(1))).squeeze(-1)
        weights = torch.softmax(energy, dim=1)
        return torch.bmm(weights.unsqueeze(1), enc).squeeze(1), weights


class Seq2Seq(GestureModel):
    """Text-only attention encoder-decoder (see the module docstring).

    Shapes: ``batch["word"]`` (B, T) int64, ``batch["pose"]`` (B, T, 141) (only the first
    ``n_pre`` frames are read) -> ``{"pose": (B, T, 141), "attention": (B, T - 1, T)}``.

    Parameters
    ----------
    config : Seq2SeqConfig
        Build one with ``beatlite.models.build_model("seq2seq", preset="tiny")``.

    Examples
    --------
    A tiny Seq2Seq on two fake windows: frame 0 is the seed's first frame, each of the T - 1 decoded frames
    attends over the T words with weights summing to 1.

    >>> import torch
    >>> from beatlite.models import build_model
    >>> from beatlite.models.testing import fake_batch
    >>> _ = torch.manual_seed(0)
    >>> model = build_model("seq2seq", preset="tiny").eval()
    >>> batch = {k: v for k, v in fake_batch(2, vocab_size=1000).items() if k in ("pose", "word")}
    >>> out = model(batch)
    >>> tuple(out["pose"].shape), tuple(out["attention"].shape)
    ((2, 34, 141), (2, 33, 34))
    >>> torch.equal(out["pose"][:, 0], batch["pose"][:, 0])
    True
    >>> bool(torch.allclose(out["attention"].sum(-1), torch.ones(2, 33)))
    True
    """

    name = "seq2seq"
    representation = "euler141"
    config_class = Seq2SeqConfig
    input_keys = ("pose", "word")

    def __init__(self, config: Seq2SeqConfig) -> None:
        super().__init__(config)
        cfg = config
        drop = cfg.dropout if cfg.n_layers > 1 else 0.0
        self.embedding = nn.Embedding(cfg.vocab_size, cfg.word_dim)
        self.encoder = nn.GRU(
            cfg.word_dim, cfg.hidden, cfg.n_layers, batch_first=True, bidirectional=True, dropout=drop
        )
        self.attention = BahdanauAttention(cfg.hidden)
        self.pre_linear = nn.Sequential(
            nn.Linear(POSE_DIM + cfg.hidden, cfg.hidden), nn.BatchNorm1d(cfg.hidden), nn.ReLU()
        )
        self.decoder = nn.GRU(cfg.hidden, cfg.hidden, cfg.n_layers, batch_first=True, dropout=drop)
        self.out = nn.Linear(cfg.hidden, POSE_DIM)

    def word_embeddings(self) -> list[nn.Embedding]:
        """The encoder's word embedding."""
        return [self.embedding]

    def _check(self, batch: Batch) -> tuple[torch.Tensor, torch.Tensor]:
        check_batch(batch, self.input_keys, "Seq2Seq")
        pose, words = batch["pose"], batch["word"]
        if pose.ndim != 3 or pose.shape[-1] != POSE_DIM or pose.shape[1] < 2:
            raise ValueError(f"Seq2Seq: batch['pose'] must be (B, T>=2, {POSE_DIM}), got {tuple(pose.shape)}")
        if words.shape != pose.shape[:2]:
            raise ValueError(
                f"Seq2Seq: batch['word'] must be (B, T) = {tuple(pose.shape[:2])}, got {tuple(words.shape)}"
            )
        check_ids(words, self.config.vocab_size, "Seq2Seq: word ids")
        return pose, words

    def forward(self, batch: Batch) -> dict[str, torch.Tensor]:
        """``{"pose": (B, T, 141), "attention": (B, T - 1, T)}`` (attention weights of steps 1..T-1)."""
        pose, words = self._check(batch)
        b, t, _ = pose.shape
        cfg = self.config
        enc, h_n = self.encoder(self.embedding(words))
        enc = sum_directions(enc, cfg.hidden)
        keys = self.attention.keys(enc)
        h = h_n.view(cfg.n_layers, 2, b, cfg.hidden).sum(dim=1).contiguous()
        frames, weights = [pose[:, 0]], []
        prev = pose[:, 0]
        for step in range(1, t):
            context, a = self.attention(h[-1], enc, keys)
            x = self.pre_linear(torch.cat([prev, context], dim=-1))
            y, h = self.decoder(x.unsqueeze(1), h)
            frame = self.out(y.squeeze(1))
            frames.append(frame)
            weights.append(a)
            prev = pose[:, step] if step < self.n_pre else frame
        return {"pose": torch.stack(frames, dim=1), "attention": torch.stack(weights, dim=1)}

    def losses(self, batch: Batch, out: dict[str, torch.Tensor], *, epoch: int) -> dict[str, torch.Tensor]:
        """``{"mse", "continuity", "variance", "total"}`` (see the module docstring).

        ``continuity = sum |out[:, t] - out[:, t-1]| / numel`` and
        ``variance = -sum_{b,d} ||out[b, :, d]||_2 / numel`` (``numel = B * T * 141``), as the
        authors normalise them; ``total`` is their weighted sum.
        """
        pred, target = out["pose"], batch["pose"]
        n = pred.numel()
        mse = nn.functional.mse_loss(pred, target)
        continuity = (pred[:, 1:] - pred[:, :-1]).abs().sum() / n
        variance = -torch.linalg.vector_norm(pred, dim=1).sum() / n
        cfg = self.config
        total = cfg.rec_weight * mse + cfg.continuity_weight * continuity + cfg.variance_weight * variance
        return {"mse": mse, "continuity": continuity, "variance": variance, "total": total}


PRESETS: dict[str, dict[str, Any]] = {
    "paper": {},
    "tiny": {"vocab_size": 1000, "word_dim": 64, "hidden": 64, "n_layers": 1, "dropout": 0.0},
}
"""``paper``: the authors' TED baseline sizes; ``tiny``: one 64-wide GRU layer each (CPU)."""
