"""HA2G's hierarchical audio learner and style coordinator (torch).

The audio encoder is a compact SE-ResNet (the reference uses SE-ResNet-34 "V2",
blocks ``[3, 4, 6, 3]``, channels ``[32, 64, 128, 256]``; HA2G §4.2, docs/reference_code.md#ha2g-audio) on a log-mel
spectrogram. Three streams read three depths of the backbone and are each mapped
to one feature vector per pose frame:

==========  ==========================  =================================  ===============
level       backbone output             stream                             per frame
==========  ==========================  =================================  ===============
``low``     layer2, (C1, 64, M/2)       Conv2d k2                          63 x C1 -> F
``mid``     layer3, (C2, 32, M/4)       PixelShuffle(2), Conv2d k3         62 x C2/4 -> F
``high``    layer4, (C3, 16, M/8)       PixelShuffle(4), Conv2d k3         62 x C3/16 -> F
==========  ==========================  =================================  ===============

For the 34-frame window the spectrogram has M = 70 frames and every stream ends with
exactly 34 time steps (70 -> 35 -> 34, 70 -> 18 -> 36 -> 34, 70 -> 9 -> 36 -> 34).

The style coordinator turns a speaker's style input into softmax weights over the
three audio levels for each body level (paper eq. 3).

Differs from HA2G's code in the layer order only (docs/reference_code.md#ha2g-audio): the code's stem and
first convolution of each block run convolution -> ReLU -> BatchNorm (here convolution -> BatchNorm -> ReLU, the
stem unbiased), and its three streams add ReLU and BatchNorm after their convolution (here none).
``order="reference"`` (``HA2GConfig.audio_order``) builds the code's order instead; trained both ways with three
seeds, the tiny model's metrics do not differ beyond two standard errors (``scripts/ha2g_audio_order.py``).

Taught in notebooks/06_ha2g.ipynb, sections 3 (the hierarchical audio learner) and 5 (the style coordinator).
"""

from __future__ import annotations

from collections.abc import Sequence

import torch
from torch import nn

from beatlite.constants import WINDOW_LENGTH
from beatlite.models.layers import match_length

AUDIO_LEVELS: tuple[str, ...] = ("low", "mid", "high")
"""Names of the three audio feature levels, in the order of the style-coordinator weights."""

LAYER_ORDERS: tuple[str, ...] = ("beatlite", "reference")
"""Values of ``HierarchicalAudioEncoder(order=)``: beatlite's conv -> BN -> ReLU, or HA2G's code's conv -> ReLU -> BN
(biased stem, ReLU and BN after each stream's convolution)."""

N_MELS = 128


class SEBlock2d(nn.Module):
    """Squeeze-and-excitation: per-channel gates from global average pooling.

    Shapes
    ------
    (B, C, H, W) -> (B, C, H, W); each channel scaled by its gate in (0, 1).

    Examples
    --------
    With the last layer's weights and bias zeroed every gate is ``sigmoid(0) = 0.5``: the input halved.

    >>> import torch
    >>> from beatlite.models.ha2g_audio import SEBlock2d
    >>> se = SEBlock2d(4, reduction=2)
    >>> _ = torch.nn.init.zeros_(se.fc[2].weight), torch.nn.init.zeros_(se.fc[2].bias)
    >>> x = torch.arange(24.0).reshape(1, 4, 2, 3)
    >>> torch.equal(se(x), x / 2)
    True
    """

    def __init__(self, channels: int, reduction: int) -> None:
        super().__init__()
        hidden = max(1, channels // reduction)
        self.fc = nn.Sequential(
            nn.Linear(channels, hidden), nn.ReLU(inplace=True), nn.Linear(hidden, channels), nn.Sigmoid()
        )

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        gate = self.fc(x.mean(dim=(2, 3)))
        return x * gate[:, :, None, None]


class SEBasicBlock2d(nn.Module):
    """Residual block ``conv3x3(stride) -> BN -> ReLU -> conv3x3 -> BN -> SE`` plus a shortcut, then ReLU.

    The shortcut is ``conv1x1(stride) + BN`` when the shape changes, else the identity.

    Shapes
    ------
    (B, in_ch, H, W) -> (B, out_ch, ceil(H / stride), ceil(W / stride))

    Examples
    --------
    Stride 2 on a 7 x 5 map: ``ceil(7 / 2) = 4`` by ``ceil(5 / 2) = 3``; the final ReLU leaves no negative value.

    >>> import torch
    >>> from beatlite.models.ha2g_audio import SEBasicBlock2d
    >>> _ = torch.manual_seed(0)
    >>> y = SEBasicBlock2d(4, 8, stride=2, reduction=4)(torch.randn(2, 4, 7, 5))
    >>> tuple(y.shape), bool((y >= 0).all())
    ((2, 8, 4, 3), True)
    """

    def __init__(self, in_ch: int, out_ch: int, stride: int, reduction: int, order: str = "beatlite") -> None:
        super().__init__()
        self.reference_order = order == "reference"  # HA2G's code: conv1 -> ReLU -> BN
        self.conv1 = nn.Conv2d(in_ch, out_ch, 3, stride=stride, padding=1, bias=False)
        self.bn1 = nn.BatchNorm2d(out_ch)
        self.conv2 = nn.Conv2d(out_ch, out_ch, 3, padding=1, bias=False)
        self.bn2 = nn.BatchNorm2d(out_ch)
        self.se = SEBlock2d(out_ch, reduction)
        self.relu = nn.ReLU(inplace=True)
        self.shortcut: nn.Module = (
            nn.Sequential(nn.Conv2d(in_ch, out_ch, 1, stride=stride, bias=False), nn.BatchNorm2d(out_ch))
            if stride != 1 or in_ch != out_ch
            else nn.Identity()
        )

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        y = self.conv1(x)
        y = self.bn1(self.relu(y)) if self.reference_order else self.relu(self.bn1(y))
        y = self.se(self.bn2(self.conv2(y)))
        return self.relu(y + self.shortcut(x))


def _layer(in_ch: int, out_ch: int, n_blocks: int, stride: int, reduction: int, order: str) -> nn.Sequential:
    blocks = [SEBasicBlock2d(in_ch, out_ch, stride, reduction, order)]
    blocks += [SEBasicBlock2d(out_ch, out_ch, 1, reduction, order) for _ in range(n_blocks - 1)]
    return nn.Sequential(*blocks)


class _Stream(nn.Module):
    """One feature stream: optional PixelShuffle, a 2-D conv (HA2G's code: then ReLU and BatchNorm), then a
    per-frame Linear."""

    def __init__(
        self,
        channels: int,
        upscale: int,
        kernel: int,
        freq_in: int,
        out_features: int,
        order: str = "beatlite",
    ) -> None:
        super().__init__()
        if channels % (upscale * upscale):
            raise ValueError(
                f"HierarchicalAudioEncoder: {channels} channels cannot be pixel-shuffled by {upscale} "
                f"(need a multiple of {upscale * upscale})"
            )
        self.shuffle: nn.Module = nn.PixelShuffle(upscale) if upscale > 1 else nn.Identity()
        ch = channels // (upscale * upscale)
        self.conv = nn.Conv2d(ch, ch, kernel)
        self.post: nn.Module = (
            nn.Sequential(nn.ReLU(inplace=True), nn.BatchNorm2d(ch))
            if order == "reference"
            else nn.Identity()
        )
        freq = freq_in * upscale - kernel + 1
        self.proj = nn.Linear(freq * ch, out_features)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        y = self.post(self.conv(self.shuffle(x)))  # (B, C', F', T')
        b, c, f, t = y.shape
        return self.proj(y.permute(0, 3, 1, 2).reshape(b, t, c * f))  # (B, T', out)


class HierarchicalAudioEncoder(nn.Module):
    """Log-mel spectrogram -> low / mid / high audio features per pose frame.

    Parameters
    ----------
    channels : 4 ints
        Output channels of the four residual layers (reference ``(32, 64, 128, 256)``).
        ``channels[2]`` must be a multiple of 4 and ``channels[3]`` of 16 (pixel shuffles).
    blocks : 4 ints
        Residual blocks per layer (reference ``(3, 4, 6, 3)``).
    reduction : int
        Squeeze-and-excitation reduction (reference 8).
    out_features : int
        Feature size F of every level (reference 32).
    levels : sequence of str
        Which of ``"low"``, ``"mid"``, ``"high"`` to compute (an ablation that never
        reads a level does not build it).
    n_frames : int
        Pose frames T per window; every stream is cropped / edge-padded to T.
    freq_stride : int
        Stride of the first convolution along the mel axis (reference 1). 2 halves the
        frequency size of every layer (the stride-(2, 1) stem of voxceleb_trainer's "fast"
        SE-ResNet-34), so the low / mid / high streams read 32 / 16 / 8 frequency rows instead of
        64 / 32 / 16; the time axis, and so the 34 output frames, is unchanged.
    order : {"beatlite", "reference"}
        Layer order (:data:`LAYER_ORDERS`): conv -> BN -> ReLU, or HA2G's code's conv -> ReLU -> BN with a biased
        stem and ReLU + BN after each stream's convolution (same weights' shapes, plus the stem bias and the
        streams' BatchNorms).

    Shapes
    ------
    mel (B, M, 128) float, dB (``power_to_db(ref=max)``, about [-80, 0]; scaled by
    ``mel / 40 + 1`` inside) -> dict level -> (B, T, F).

    Examples
    --------
    The ``tiny`` HA2G's encoder on the 70 mel frames of a 34-frame window: every level gives 34 frames of
    F = 16 features; an ablation reading one level builds only that stream.

    >>> import torch
    >>> from beatlite.models.ha2g_audio import HierarchicalAudioEncoder
    >>> _ = torch.manual_seed(0)
    >>> encoder = HierarchicalAudioEncoder((4, 8, 16, 32), (1, 1, 1, 1), 4, 16, freq_stride=2)
    >>> mel = -80.0 * torch.rand(2, 70, 128)
    >>> {level: tuple(f.shape) for level, f in encoder(mel).items()}
    {'low': (2, 34, 16), 'mid': (2, 34, 16), 'high': (2, 34, 16)}
    >>> low_only = HierarchicalAudioEncoder((4, 8, 16, 32), (1, 1, 1, 1), 4, 16, levels=("low",), freq_stride=2)
    >>> list(low_only(mel)), low_only.layer3 is None
    (['low'], True)
    """

    def __init__(
        self,
        channels: Sequence[int] = (32, 64, 128, 256),
        blocks: Sequence[int] = (3, 4, 6, 3),
        reduction: int = 8,
        out_features: int = 32,
        levels: Sequence[str] = AUDIO_LEVELS,
        n_frames: int = WINDOW_LENGTH,
        freq_stride: int = 1,
        order: str = "beatlite",
    ) -> None:
        super().__init__()
        if order not in LAYER_ORDERS:
            raise ValueError(f"order must be one of {LAYER_ORDERS}, got {order!r}")
        c = tuple(int(v) for v in channels)
        nb = tuple(int(v) for v in blocks)
        if len(c) != 4 or len(nb) != 4 or min(c) < 1 or min(nb) < 1:
            raise ValueError(f"channels and blocks must be 4 positive ints, got {c} and {nb}")
        unknown = sorted(set(levels) - set(AUDIO_LEVELS))
        if unknown or not levels:
            raise ValueError(f"levels must be a non-empty subset of {AUDIO_LEVELS}, got {tuple(levels)}")
        self.levels = tuple(lv for lv in AUDIO_LEVELS if lv in levels)
        self.n_frames = int(n_frames)
        fs = int(freq_stride)
        if fs not in (1, 2, 4):
            raise ValueError(f"freq_stride must be 1, 2 or 4, got {freq_stride}")
        ref = order == "reference"  # HA2G's code: a biased stem conv, then ReLU before BatchNorm
        stem = nn.Conv2d(1, c[0], 3, stride=(fs, 1), padding=1, bias=ref)
        norm_act = (
            (nn.ReLU(inplace=True), nn.BatchNorm2d(c[0]))
            if ref
            else (nn.BatchNorm2d(c[0]), nn.ReLU(inplace=True))
        )
        self.stem = nn.Sequential(stem, *norm_act)
        self.layer1 = _layer(c[0], c[0], nb[0], 1, reduction, order)
        self.layer2 = _layer(c[0], c[1], nb[1], 2, reduction, order)
        need3 = "mid" in self.levels or "high" in self.levels
        need4 = "high" in self.levels
        self.layer3 = _layer(c[1], c[2], nb[2], 2, reduction, order) if need3 else None
        self.layer4 = _layer(c[2], c[3], nb[3], 2, reduction, order) if need4 else None
        streams: dict[str, nn.Module] = {}
        if "low" in self.levels:
            streams["low"] = _Stream(c[1], 1, 2, N_MELS // (2 * fs), out_features, order)
        if "mid" in self.levels:
            streams["mid"] = _Stream(c[2], 2, 3, N_MELS // (4 * fs), out_features, order)
        if "high" in self.levels:
            streams["high"] = _Stream(c[3], 4, 3, N_MELS // (8 * fs), out_features, order)
        self.streams = nn.ModuleDict(streams)
        self.out_features = int(out_features)

    def forward(self, mel: torch.Tensor) -> dict[str, torch.Tensor]:
        if mel.ndim != 3 or mel.shape[2] != N_MELS or mel.shape[1] < 8:
            raise ValueError(
                f"HierarchicalAudioEncoder: mel must be (B, M >= 8, {N_MELS}), got shape {tuple(mel.shape)}"
            )
        x = (mel / 40.0 + 1.0).transpose(1, 2).unsqueeze(1).contiguous()  # (B, 1, 128 mels, M frames)
        x2 = self.layer2(self.layer1(self.stem(x)))
        feats = {"low": x2}
        if self.layer3 is not None:
            feats["mid"] = self.layer3(x2)
            if self.layer4 is not None:
                feats["high"] = self.layer4(feats["mid"])
        out = {}
        for level in self.levels:
            y = self.streams[level](feats[level])
            out[level] = match_length(y, self.n_frames)
        return out


class StyleCoordinator(nn.Module):
    """Speaker style input -> softmax weights of the three audio levels for each body level.

    ``ELU -> Linear(z_dim, hidden) -> ELU -> Linear(hidden, 3 * n_body_levels)``, reshaped to
    ``(B, 3, H)`` and soft-maxed over the 3 audio levels (paper eq. 3; reference: hidden 32,
    H = 6). Its input is the coordinator's own speaker embedding (``Embedding -> Linear``, not
    sampled) in HA2G's design (``HA2GConfig.style="reference"``), the shared style z otherwise.

    Shapes
    ------
    (B, z_dim) -> (B, 3, H); every column sums to 1.

    Examples
    --------
    >>> import torch
    >>> from beatlite.models.ha2g_audio import StyleCoordinator
    >>> _ = torch.manual_seed(0)
    >>> w = StyleCoordinator(z_dim=8, hidden=16, n_body_levels=6)(torch.randn(2, 8))
    >>> tuple(w.shape), bool(torch.allclose(w.sum(1), torch.ones(2, 6))), bool((w > 0).all())
    ((2, 3, 6), True, True)
    """

    def __init__(self, z_dim: int, hidden: int, n_body_levels: int) -> None:
        super().__init__()
        self.n_body_levels = int(n_body_levels)
        self.net = nn.Sequential(
            nn.ELU(), nn.Linear(z_dim, hidden), nn.ELU(), nn.Linear(hidden, 3 * self.n_body_levels)
        )

    def forward(self, z: torch.Tensor) -> torch.Tensor:
        if z.ndim != 2:
            raise ValueError(f"StyleCoordinator: z must be (B, z_dim), got shape {tuple(z.shape)}")
        return torch.softmax(self.net(z).view(z.shape[0], 3, self.n_body_levels), dim=1)


def blend_audio(features: dict[str, torch.Tensor], weights: torch.Tensor) -> torch.Tensor:
    """Paper eq. 3: ``f^h = w_low[h] f_low + w_mid[h] f_mid + w_high[h] f_high`` for each body level h.

    Parameters
    ----------
    features : dict level -> (B, T, F)
        The three audio levels.
    weights : (B, 3, H)
        Style-coordinator weights (rows in :data:`AUDIO_LEVELS` order).

    Returns
    -------
    (B, H, T, F)
        The blended audio feature of every body level.

    Examples
    --------
    Constant levels 1 (low), 2 (mid) and 3 (high); body level 0 weighs low and mid by half each (1.5),
    body level 1 takes the high level alone (3).

    >>> import torch
    >>> from beatlite.models.ha2g_audio import blend_audio
    >>> features = {level: torch.full((1, 2, 1), v) for level, v in (("low", 1.0), ("mid", 2.0), ("high", 3.0))}
    >>> weights = torch.tensor([[[0.5, 0.0], [0.5, 0.0], [0.0, 1.0]]])  # (B, 3 audio levels, H = 2)
    >>> blend_audio(features, weights)[0, :, :, 0]
    tensor([[1.5000, 1.5000],
            [3.0000, 3.0000]])
    """
    stacked = torch.stack([features[level] for level in AUDIO_LEVELS], dim=1)  # (B, 3, T, F)
    return torch.einsum("bsh,bstf->bhtf", weights, stacked)
