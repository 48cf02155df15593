"""CaMN, the Cascaded Motion Network of BEAT (ECCV 2022, §4), runnable on a CPU.

Data flow for a window batch (T = 34 frames at 15 fps; sizes of the ``paper`` preset)::

    word (B,T)      -> TextEncoderTCN             -> text  (B,T,128)
    speaker (B,)    -> Embedding+Linear+LReLU     -> spk   (B,T,8)    (repeated over time)
    emotion (B,T)   -> Embedding+Linear, 4 convs  -> emo   (B,T,8)
    audio (B,36266) -> WavEncoder (6 BasicBlocks) -> wav   (B,T,128)
    cat[wav, emo, spk, text]            -> audio fusion MLP  -> fa (B,T,128)   \\ the cascade
    face (B,T,51) -> BasicBlocks -> (B,T,32); cat[face, fa, emo, spk, text] -> face fusion -> ff (B,T,32)
    pre_seq (B,T,142) = seed pose (first 4 frames) + indicator bit
    x = cat[pre_seq, spk, emo, text, fa, ff]                                 (B,T,446)
    body  = MLP(sum-of-directions biLSTM(x))                                 (B,T,27)
    hands = MLP(sum-of-directions biLSTM(cat[x, body]))                      (B,T,114)
    pose  = camn_assemble(body, hands)                                       (B,T,141)

Switches (config fields): ``use_audio``, ``use_text``, ``use_face``, ``use_emotion``,
``use_speaker`` drop a modality (its encoder is not built and its features are removed
from every concatenation); ``cascade=False`` is the paper's "w/o cascaded" end-to-end
variant: no fusion MLPs (encoder features go straight into the decoder) and one
decoder LSTM predicting all 141 channels; ``semantic_weighting=False`` drops the
(1 + semantic) loss weighting.

Losses (docs/reference_code.md#camn-losses): ``rec_weight * Huber_0.1((1+s) * pred, (1+s) * target)`` and, from
epoch ``no_adv_epochs`` on, ``adv_weight * -log D(pred)`` (NS-GAN) with a working
:class:`~beatlite.models.layers.ConvDiscriminator`. ``squared_adv_loss=True`` reproduces
the reference's generator term ``adv_weight * D(pred)**2`` (a bug: minimising it pushes
D(pred) towards 0, i.e. it rewards looking *fake*); it exists only for comparison.

Taught in notebooks/05_camn.ipynb, section 2 (the architecture, piece by piece).
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
import torch
from torch import nn

from beatlite.constants import N_SPEAKERS
from beatlite.models.base import (
    AdversarialConfig,
    Batch,
    GestureModel,
    TextConfig,
    check_batch,
    huber,
    seed_input,
)
from beatlite.models.layers import (
    BasicBlock1d,
    ConvDiscriminator,
    TextEncoderTCN,
    WavEncoder,
    check_ids,
    match_length,
    mlp,
    ns_gan_d_loss,
    ns_gan_g_loss,
    run_lstm,
    sum_directions,
)

BODY_DIM = 27
HANDS_DIM = 114
POSE_DIM = 141


@dataclasses.dataclass
class CaMNConfig(TextConfig, AdversarialConfig):
    """CaMN hyper-parameters (defaults = the ``paper`` preset, BEAT §4, docs/reference_code.md#camn).

    Sizes are feature channels per frame; ``hidden``/``n_layers`` are the decoder LSTMs'.
    ``no_adv_epochs`` is the 0-based epoch from which the adversarial term is on. The text and
    discriminator fields are :class:`~beatlite.models.base.TextConfig`'s and
    :class:`~beatlite.models.base.AdversarialConfig`'s (CaMN's own defaults redeclared here).
    """

    preset: str = "paper"
    text_hidden: int = 256
    text_features: int = 128
    n_speakers: int = N_SPEAKERS
    speaker_features: int = 8
    n_emotions: int = 8
    emotion_features: int = 8
    audio_channels: tuple[int, ...] = (32, 32, 32, 64, 64, 128)
    audio_fused: int = 128
    face_channels: tuple[int, ...] = (16, 16, 16, 32)
    face_fused: int = 32
    hidden: int = 256
    n_layers: int = 4
    head_hidden: int = 128
    dropout: float = 0.3
    slope: float = 0.1
    use_audio: bool = True
    use_text: bool = True
    use_face: bool = True
    use_emotion: bool = True
    use_speaker: bool = True
    cascade: bool = True
    semantic_weighting: bool = True
    rec_weight: float = 500.0
    no_adv_epochs: int = 40
    squared_adv_loss: bool = False

    def __post_init__(self) -> None:
        self.audio_channels = tuple(int(c) for c in self.audio_channels)
        self.face_channels = tuple(int(c) for c in self.face_channels)
        if len(self.audio_channels) != 6:
            raise ValueError(f"audio_channels must have 6 entries, got {self.audio_channels}")
        if len(self.face_channels) != 4:
            raise ValueError(f"face_channels must have 4 entries, got {self.face_channels}")


PRESETS: dict[str, dict[str, Any]] = {
    "paper": {},
    "tiny": {
        "vocab_size": 1000,
        "word_dim": 64,
        "text_hidden": 48,
        "text_layers": 2,
        "text_features": 32,
        "n_speakers": 30,
        "audio_channels": (4, 8, 8, 16, 16, 32),
        "audio_fused": 32,
        "face_channels": (8, 8, 8, 16),
        "face_fused": 16,
        "hidden": 64,
        "n_layers": 1,
        "head_hidden": 64,
        "dropout": 0.1,
        "adv_weight": 0.5,
        "no_adv_epochs": 10,
        "d_hidden": 32,
        "d_layers": 1,
    },
}
"""Preset name -> overrides of :class:`CaMNConfig` (``paper``: docs/reference_code.md#camn; ``tiny``: CPU minutes).

``tiny`` keeps every component of ``paper`` (six-block WavEncoder, TCN text encoder, face,
emotion and speaker encoders, the cascade, body-then-hands decoders, discriminator) with
narrower layers. The WavEncoder dominates the cost (its first blocks run at 7891 steps per
window), so its first block has 4 channels: with ``(4, 8, 8, 16, 16, 32)`` a generator step
on 32 windows is about 1.2x faster than with ``(8, 8, 8, 16, 16, 32)`` (0.29 vs 0.35 s on one
thread of a busy machine, interleaved A/B; whole-epoch timings on a shared machine are too noisy
to show it). The shipped training schedule is in
``beatlite.train.recipes.RECIPES`` (40 epochs at lr 2e-3, best epoch by validation FGD).
"""


def _assembly_index() -> torch.Tensor:
    """(141,) index into ``cat[body27, hands114]`` giving the reference's 141-d layout.

    Computed by :func:`beatlite.skeleton.beat.camn_assemble` on index arrays
    (docs/reference_code.md#camn-decoders: out[0:18] = body[0:18], out[18:75] = hands[0:57],
    out[75:84] = body[18:27], out[84:141] = hands[57:114]).
    """
    from beatlite.skeleton.beat import camn_assemble

    body = np.arange(BODY_DIM, dtype=np.float64)
    hands = np.arange(BODY_DIM, BODY_DIM + HANDS_DIM, dtype=np.float64)
    index = np.asarray(camn_assemble(body[None], hands[None]))[0]
    return torch.as_tensor(np.rint(index).astype(np.int64))


class SpeakerEncoder(nn.Module):
    """``Embedding(n, f) -> Linear(f, f) -> LReLU(0.1)``: (B,) int64 speaker ids in ``0..n-1`` -> (B, f).

    Examples
    --------
    One feature vector per window; two windows of one speaker get the same one.

    >>> import torch
    >>> from beatlite.models.camn import SpeakerEncoder
    >>> _ = torch.manual_seed(0)
    >>> z = SpeakerEncoder(n_speakers=4, features=8)(torch.tensor([3, 1, 3]))
    >>> tuple(z.shape), torch.equal(z[0], z[2])
    ((3, 8), True)
    """

    def __init__(self, n_speakers: int, features: int, slope: float = 0.1) -> None:
        super().__init__()
        self.embedding = nn.Embedding(n_speakers, features)
        self.mlp = mlp([features, features], slope)

    def forward(self, speaker: torch.Tensor) -> torch.Tensor:
        if speaker.ndim != 1:
            raise ValueError(f"speaker must be (B,), got shape {tuple(speaker.shape)}")
        check_ids(speaker, self.embedding.num_embeddings, "speaker ids")
        return self.mlp(self.embedding(speaker))


class EmotionEncoder(nn.Module):
    """``Embedding(8, f) -> Linear(f, f)`` then 4 x [Conv1d(k9, p4) + BN + LReLU(0.3)], f -> f -> 2f -> 2f -> f.

    Shapes: (B, T) int64 emotion ids in ``0..n_emotions-1`` -> (B, T, f); the k9 convolutions keep T.

    Examples
    --------
    >>> import torch
    >>> from beatlite.models.camn import EmotionEncoder
    >>> _ = torch.manual_seed(0)
    >>> tuple(EmotionEncoder(n_emotions=8, features=8)(torch.zeros(2, 34, dtype=torch.long)).shape)
    (2, 34, 8)
    """

    def __init__(self, n_emotions: int, features: int) -> None:
        super().__init__()
        self.embedding = nn.Embedding(n_emotions, features)
        self.linear = nn.Linear(features, features)
        chans = [features, features, 2 * features, 2 * features, features]
        layers: list[nn.Module] = []
        for a, b in zip(chans[:-1], chans[1:], strict=True):
            layers += [nn.Conv1d(a, b, 9, padding=4), nn.BatchNorm1d(b), nn.LeakyReLU(0.3)]
        self.convs = nn.Sequential(*layers)

    def forward(self, emotion: torch.Tensor) -> torch.Tensor:
        if emotion.ndim != 2:
            raise ValueError(f"emotion must be (B, T), got shape {tuple(emotion.shape)}")
        check_ids(emotion, self.embedding.num_embeddings, "emotion ids")
        x = self.linear(self.embedding(emotion)).transpose(1, 2)
        return self.convs(x).transpose(1, 2)


class FaceEncoder(nn.Module):
    """51 ARKit weights -> ``channels[-1]`` features per frame with 4 length-preserving BasicBlocks.

    Blocks (docs/reference_code.md#camn-encoders): (51 -> c0, k7, p3)*, (c0 -> c1, k3, p1)*, (c1 -> c2, k3, p1), (c2 -> c3, k3, p1)*.
    Shapes: (B, T, 51) blendshape weights in [0, 1] -> (B, T, channels[-1]).

    Examples
    --------
    >>> import torch
    >>> from beatlite.models.camn import FaceEncoder
    >>> _ = torch.manual_seed(0)
    >>> tuple(FaceEncoder((8, 8, 8, 16))(torch.rand(2, 34, 51)).shape)
    (2, 34, 16)
    """

    def __init__(self, channels: tuple[int, ...] = (16, 16, 16, 32)) -> None:
        super().__init__()
        c = channels
        self.blocks = nn.Sequential(
            BasicBlock1d(51, c[0], 7, 1, 3, downsample=True),
            BasicBlock1d(c[0], c[1], 3, 1, 1, downsample=True),
            BasicBlock1d(c[1], c[2], 3, 1, 1, downsample=c[1] != c[2]),
            BasicBlock1d(c[2], c[3], 3, 1, 1, downsample=True),
        )

    def forward(self, face: torch.Tensor) -> torch.Tensor:
        if face.ndim != 3 or face.shape[-1] != 51:
            raise ValueError(f"face must be (B, T, 51), got shape {tuple(face.shape)}")
        return self.blocks(face.transpose(1, 2)).transpose(1, 2)


class _Decoder(nn.Module):
    """Bidirectional LSTM (directions summed) + ``Linear(h, head) -> LReLU -> Linear(head, out)``."""

    def __init__(self, in_size: int, out_size: int, cfg: CaMNConfig) -> None:
        super().__init__()
        self.hidden = cfg.hidden
        self.lstm = nn.LSTM(
            in_size,
            cfg.hidden,
            num_layers=cfg.n_layers,
            batch_first=True,
            bidirectional=True,
            dropout=cfg.dropout if cfg.n_layers > 1 else 0.0,
        )
        self.head = nn.Sequential(
            nn.Linear(cfg.hidden, cfg.head_hidden),
            nn.LeakyReLU(cfg.slope),
            nn.Linear(cfg.head_hidden, out_size),
        )

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.head(sum_directions(run_lstm(self.lstm, x), self.hidden))


def _context_encoders(
    cfg: CaMNConfig,
) -> tuple[SpeakerEncoder | None, EmotionEncoder | None, TextEncoderTCN | None]:
    """The speaker, emotion and text encoders (None where switched off), built in that order."""
    speaker = SpeakerEncoder(cfg.n_speakers, cfg.speaker_features, cfg.slope) if cfg.use_speaker else None
    emotion = EmotionEncoder(cfg.n_emotions, cfg.emotion_features) if cfg.use_emotion else None
    text = (
        TextEncoderTCN(
            cfg.vocab_size, cfg.word_dim, cfg.text_hidden, cfg.text_layers, cfg.text_features, cfg.dropout
        )
        if cfg.use_text
        else None
    )
    return speaker, emotion, text


def _context_width(cfg: CaMNConfig) -> int:
    """Width of the shared context [speaker, emotion, text] (the features switched on)."""
    widths = (
        (cfg.use_speaker, cfg.speaker_features),
        (cfg.use_emotion, cfg.emotion_features),
        (cfg.use_text, cfg.text_features),
    )
    return sum(width for on, width in widths if on)


def _fused_widths(cfg: CaMNConfig) -> tuple[int, int]:
    """Widths of the audio and face features the decoder receives (0 where switched off).

    In the cascade they are the fusion MLPs' outputs, otherwise the encoders' last channels.
    """
    if cfg.cascade:
        return (cfg.audio_fused if cfg.use_audio else 0), (cfg.face_fused if cfg.use_face else 0)
    return (cfg.audio_channels[-1] if cfg.use_audio else 0), (cfg.face_channels[-1] if cfg.use_face else 0)


class CaMN(GestureModel):
    """Cascaded Motion Network (see the module docstring).

    Parameters
    ----------
    config : CaMNConfig
        Build one with ``beatlite.models.build_model("camn", preset="tiny", **switches)``.

    Notes
    -----
    ``forward(batch)`` returns ``{"pose": (B,T,141), "body": (B,T,27), "hands": (B,T,114)}``
    (without the cascade ``body``/``hands`` are the corresponding slices of ``pose``).
    Reads ``batch["pose"]`` only through its first ``n_pre = 4`` frames (the seed).

    Examples
    --------
    A tiny CaMN on two fake windows of every modality: the body decoder's 27 channels and the hands decoder's
    114 are interleaved into the reference's 141-channel layout, whose first 18 channels are the body's first 18.

    >>> import torch
    >>> from beatlite.models import build_model
    >>> from beatlite.models.testing import fake_batch
    >>> _ = torch.manual_seed(0)
    >>> model = build_model("camn", preset="tiny")
    >>> batch = fake_batch(2, vocab_size=1000)
    >>> out = model(batch)
    >>> tuple(out["pose"].shape), tuple(out["body"].shape), tuple(out["hands"].shape)
    ((2, 34, 141), (2, 34, 27), (2, 34, 114))
    >>> torch.equal(out["pose"][..., :18], out["body"][..., :18])
    True

    The ablation switches change what the model reads (and :meth:`batch_keys` adds the loss's ``semantic``):

    >>> type(model).batch_keys(build_model("camn", preset="tiny", use_audio=False, use_face=False).config)
    ('pose', 'word', 'emotion', 'speaker', 'semantic')
    """

    name = "camn"
    representation = "euler141"
    config_class = CaMNConfig

    def __init__(self, config: CaMNConfig) -> None:
        super().__init__(config)
        cfg = config
        self.register_buffer("assembly", _assembly_index(), persistent=False)
        # modules are built in this order (it fixes the random initialisation and the state_dict order)
        self.speaker_encoder, self.emotion_encoder, self.text_encoder = _context_encoders(cfg)
        ctx = _context_width(cfg)  # width of the shared context [emo, spk, text]
        self.audio_encoder = WavEncoder(cfg.audio_channels) if cfg.use_audio else None
        self.face_encoder = FaceEncoder(cfg.face_channels) if cfg.use_face else None
        audio_out, face_out = _fused_widths(cfg)
        self.audio_fusion: nn.Module | None = None
        self.face_fusion: nn.Module | None = None
        if cfg.cascade:
            if cfg.use_audio:
                self.audio_fusion = mlp(
                    [cfg.audio_channels[-1] + ctx, cfg.audio_fused, cfg.audio_fused], cfg.slope
                )
            if cfg.use_face:
                widths = [cfg.face_channels[-1] + audio_out + ctx, cfg.audio_fused, cfg.face_fused]
                self.face_fusion = mlp(widths, cfg.slope)
        in_size = POSE_DIM + 1 + ctx + audio_out + face_out
        self.decoder_in = in_size
        if cfg.cascade:
            self.body_decoder = _Decoder(in_size, BODY_DIM, cfg)
            self.hands_decoder: _Decoder | None = _Decoder(in_size + BODY_DIM, HANDS_DIM, cfg)
        else:
            self.body_decoder = _Decoder(in_size, POSE_DIM, cfg)
            self.hands_decoder = None
        if cfg.adversarial:
            self.discriminator = ConvDiscriminator(
                POSE_DIM, hidden=cfg.d_hidden, n_layers=cfg.d_layers, n_frames=cfg.n_frames, slope=cfg.slope
            )

    @classmethod
    def keys_for(cls, config: CaMNConfig) -> tuple[str, ...]:
        """Batch keys read with ``config``: ``pose`` plus every modality switched on."""
        keys = ["pose"]
        for flag, key in (
            (config.use_audio, "audio"),
            (config.use_text, "word"),
            (config.use_face, "face"),
            (config.use_emotion, "emotion"),
            (config.use_speaker, "speaker"),
        ):
            if flag:
                keys.append(key)
        return tuple(keys)

    @classmethod
    def batch_keys(cls, config: CaMNConfig) -> tuple[str, ...]:
        """:meth:`keys_for` plus ``semantic`` when the loss is semantic-weighted."""
        return (*cls.keys_for(config), *(("semantic",) if config.semantic_weighting else ()))

    @property
    def input_keys(self) -> tuple[str, ...]:  # type: ignore[override]
        """Batch keys the forward pass reads (:meth:`keys_for` of its config)."""
        return self.keys_for(self.config)

    def word_embeddings(self) -> list[nn.Embedding]:
        """The text encoder's embedding (none without text)."""
        return [] if self.text_encoder is None else [self.text_encoder.embedding]

    def encode(self, batch: Batch) -> dict[str, torch.Tensor]:
        """Per-modality features, each (B, T, C): keys ``text, speaker, emotion, audio, face`` (those on)."""
        pose = batch["pose"]
        b, t, _ = pose.shape
        feats: dict[str, torch.Tensor] = {}
        if self.speaker_encoder is not None:
            feats["speaker"] = self.speaker_encoder(batch["speaker"]).unsqueeze(1).expand(b, t, -1)
        if self.emotion_encoder is not None:
            feats["emotion"] = match_length(self.emotion_encoder(batch["emotion"]), t)
        if self.text_encoder is not None:
            feats["text"] = match_length(self.text_encoder(batch["word"]), t)
        if self.audio_encoder is not None:
            feats["audio"] = match_length(self.audio_encoder(batch["audio"]), t)
        if self.face_encoder is not None:
            feats["face"] = match_length(self.face_encoder(batch["face"]), t)
        return feats

    def forward(self, batch: Batch) -> dict[str, torch.Tensor]:
        """``{"pose": (B,T,141), "body": (B,T,27), "hands": (B,T,114)}`` in z-scored Euler units."""
        check_batch(batch, self.input_keys, "CaMN")
        pose = batch["pose"]
        if pose.ndim != 3 or pose.shape[-1] != POSE_DIM:
            raise ValueError(f"CaMN: batch['pose'] must be (B, T, {POSE_DIM}), got shape {tuple(pose.shape)}")
        x = self._decoder_input(pose, self.encode(batch))
        if self.hands_decoder is None:
            out = self.body_decoder(x)
            return {"pose": out, **self._split(out)}
        body = self.body_decoder(x)
        hands = self.hands_decoder(torch.cat([x, body], -1))
        return {"pose": torch.cat([body, hands], -1)[..., self.assembly], "body": body, "hands": hands}

    def _decoder_input(self, pose: torch.Tensor, feats: dict[str, torch.Tensor]) -> torch.Tensor:
        """(B, T, decoder_in): seed frames, context, then the audio and face features (fused in the cascade)."""
        ctx = [feats[k] for k in ("emotion", "speaker", "text") if k in feats]
        parts = [
            seed_input(pose, self.n_pre),
            *[feats[k] for k in ("speaker", "emotion", "text") if k in feats],
        ]
        fused_audio = None
        if "audio" in feats:
            fused_audio = (
                self.audio_fusion(torch.cat([feats["audio"], *ctx], -1))
                if self.config.cascade
                else feats["audio"]
            )
            parts.append(fused_audio)
        if "face" in feats:
            if self.config.cascade:
                extra = [fused_audio] if fused_audio is not None else []
                parts.append(self.face_fusion(torch.cat([feats["face"], *extra, *ctx], -1)))
            else:
                parts.append(feats["face"])
        return torch.cat(parts, -1)

    def _split(self, pose: torch.Tensor) -> dict[str, torch.Tensor]:
        """Inverse assembly: the body (27) and hands (114) channels of a 141-d pose."""
        inverse = torch.empty_like(self.assembly)
        inverse[self.assembly] = torch.arange(POSE_DIM, device=self.assembly.device)
        both = pose[..., inverse]
        return {"body": both[..., :BODY_DIM], "hands": both[..., BODY_DIM:]}

    def reconstruction_loss(self, batch: Batch, pred: torch.Tensor) -> torch.Tensor:
        """``Huber_0.1((1+s) pred, (1+s) target)`` (s = per-frame semantic score) or plain Huber when off."""
        target = batch["pose"]
        if self.config.semantic_weighting:
            check_batch(batch, ("semantic",), "CaMN.losses")
            w = 1.0 + batch["semantic"].to(pred.dtype).unsqueeze(-1)
            return huber(pred * w, target * w)
        return huber(pred, target)

    def losses(self, batch: Batch, out: dict[str, torch.Tensor], *, epoch: int) -> dict[str, torch.Tensor]:
        """``{"rec", "adv", "total"}``; ``adv`` is 0 before ``no_adv_epochs`` or without a discriminator."""
        cfg = self.config
        rec = self.reconstruction_loss(batch, out["pose"])
        adv = rec.new_zeros(())
        if self.adversarial_active(epoch):
            logit = self.discriminator(out["pose"])
            if cfg.squared_adv_loss:
                adv = (torch.sigmoid(logit) ** 2).mean()
            else:
                adv = ns_gan_g_loss(logit)
        total = cfg.rec_weight * rec + cfg.adv_weight * adv
        return {"rec": rec, "adv": adv, "total": total}

    def discriminator_losses(self, batch: Batch, out: dict[str, torch.Tensor]) -> dict[str, torch.Tensor]:
        """NS-GAN discriminator loss on real ``batch["pose"]`` vs detached ``out["pose"]``."""
        if self.discriminator is None:
            raise RuntimeError("CaMN was built with adversarial=False: it has no discriminator")
        real = self.discriminator(batch["pose"])
        fake = self.discriminator(out["pose"].detach())
        d = ns_gan_d_loss(real, fake)
        return {"d": d, "total": d}


#: The parts of :class:`CaMN`, in the order of the data flow (encoders, fusions, decoders, discriminator).
PARTS = (
    "text_encoder",
    "speaker_encoder",
    "emotion_encoder",
    "audio_encoder",
    "face_encoder",
    "audio_fusion",
    "face_fusion",
    "body_decoder",
    "hands_decoder",
    "discriminator",
)


def input_widths(config: CaMNConfig) -> dict[str, int]:
    """The input width of each fusion and decoder, computed from a configuration (BEAT §4, Fig. 5).

    The context is emotion + speaker + text features; the audio fusion reads the last audio
    channels and the context; the face fusion the last face channels, the fused audio and the
    context; the body decoder the seed pose (141 angles + 1 indicator bit), the context and both
    fused features; the hands decoder the same plus the 27 body outputs. The ``use_*`` switches and
    ``cascade`` are honoured: a modality switched off adds nothing, and a part that is not built (a fusion
    of a modality switched off, both fusions and the hands decoder without the cascade) has width 0.

    Returns
    -------
    dict
        ``{"audio fusion in", "face fusion in", "body decoder in", "hands decoder in"}`` -> width
        (channels per frame).

    Examples
    --------
    >>> w = input_widths(CaMNConfig(**PRESETS["paper"], preset="paper"))
    >>> w["body decoder in"], w["hands decoder in"]  # 142 + 144 + 128 + 32 and + 27
    (446, 473)

    Without audio the body decoder reads 128 channels fewer and the audio fusion is not built:

    >>> w = input_widths(CaMNConfig(**PRESETS["paper"], preset="paper", use_audio=False))
    >>> w["audio fusion in"], w["body decoder in"]
    (0, 318)
    """
    ctx = _context_width(config)
    audio_out, face_out = _fused_widths(config)
    body = POSE_DIM + 1 + ctx + audio_out + face_out
    cascade = config.cascade
    return {
        "audio fusion in": config.audio_channels[-1] + ctx if cascade and config.use_audio else 0,
        "face fusion in": config.face_channels[-1] + audio_out + ctx if cascade and config.use_face else 0,
        "body decoder in": body,
        "hands decoder in": body + BODY_DIM if cascade else 0,
    }


def part_parameters(model: CaMN) -> dict[str, int]:
    """Number of parameters of each of :data:`PARTS` of ``model`` (0 for a part not built), plus ``"total"``.

    Examples
    --------
    The speaker encoder of the ``tiny`` preset is an ``Embedding(30, 8)`` and a ``Linear(8, 8)``:
    ``30 * 8 + 8 * 8 + 8 = 312`` parameters. Without audio there is no audio encoder or audio fusion,
    and the parts still add up to the total.

    >>> from beatlite.models import build_model
    >>> from beatlite.models.camn import PARTS, part_parameters
    >>> part_parameters(build_model("camn", preset="tiny"))["speaker_encoder"]
    312
    >>> counts = part_parameters(build_model("camn", preset="tiny", use_audio=False))
    >>> counts["audio_encoder"], counts["audio_fusion"], sum(counts[p] for p in PARTS) == counts["total"]
    (0, 0, True)
    """
    modules = {part: getattr(model, part) for part in PARTS}
    counts = {k: 0 if m is None else sum(p.numel() for p in m.parameters()) for k, m in modules.items()}
    return {**counts, "total": int(model.n_parameters())}
