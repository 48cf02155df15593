"""Building blocks shared by CaMN and the baselines (torch).

All blocks work on channel-first sequences ``(B, C, T)`` unless said otherwise.

LeakyReLU slopes: the reference code wrote ``nn.LeakyReLU(True)`` in many places,
which sets ``negative_slope=1.0`` (an identity, so those MLPs were linear; fixed
upstream in PantoMatrix PR #52). beatlite uses the corrected slopes: 0.1 in fusion
MLPs, output heads and the discriminator, 0.01 (torch's default, as the reference)
inside the residual :class:`BasicBlock1d`, 0.3 in the emotion encoder and the
Trimodal wave encoder.

Taught in notebooks/05_camn.ipynb, sections 2.1 (audio: from 36266 samples to 34 frames) and 2.2 (text, speaker, emotion and face).
"""

from __future__ import annotations

import functools
from collections.abc import Sequence

import torch
from torch import nn
from torch.nn.utils.parametrizations import weight_norm

from beatlite.constants import WINDOW_LENGTH


class BasicBlock1d(nn.Module):
    """timm-style residual block on 1-D sequences (CaMN's ``BasicBlock``).

    ``conv(k, stride, padding) -> BN -> LReLU -> conv(k, 1, k//2) -> BN``, plus a shortcut
    (``conv(k, stride, padding) + BN`` when ``downsample`` else identity), then LReLU.

    Parameters
    ----------
    in_ch, out_ch : int
        Channels in / out.
    kernel : int
        Kernel size of both convolutions (odd).
    stride : int
        Stride of the first convolution (and of the shortcut).
    padding : int
        Padding of the first convolution (the reference's ``first_dilation``).
    downsample : bool
        Use a convolutional shortcut (required when shape changes).
    slope : float
        LeakyReLU negative slope (reference: torch default 0.01).

    Shapes
    ------
    (B, in_ch, L) -> (B, out_ch, floor((L + 2 padding - kernel) / stride) + 1)

    Examples
    --------
    100 samples, kernel 15, stride 5, padding 7: ``floor((100 + 14 - 15) / 5) + 1 = 20`` frames. An identity
    shortcut needs the shape kept:

    >>> import torch
    >>> from beatlite.models.layers import BasicBlock1d
    >>> _ = torch.manual_seed(0)
    >>> tuple(BasicBlock1d(1, 4, 15, 5, 7, downsample=True)(torch.randn(2, 1, 100)).shape)
    (2, 4, 20)
    >>> BasicBlock1d(1, 4, 15, 5, 7)
    Traceback (most recent call last):
    ...
    ValueError: BasicBlock1d: an identity shortcut needs in_ch == out_ch, stride 1 and 'same' padding; got in_ch=1, out_ch=4, stride=5, padding=7, kernel=15
    """

    frames_as_matmul: bool = False
    """Compute the two first convolutions (``conv1`` and the shortcut's, which read the same one-channel
    input) as one matrix product of the input's frames (:func:`frame_conv1d`) instead of two convolution
    kernels: the same values to float rounding, the same parameters. Set by :func:`use_frame_matmul`."""

    def __init__(
        self,
        in_ch: int,
        out_ch: int,
        kernel: int,
        stride: int = 1,
        padding: int = 0,
        *,
        downsample: bool = False,
        slope: float = 0.01,
    ) -> None:
        super().__init__()
        if not downsample and (in_ch != out_ch or stride != 1 or 2 * padding != kernel - 1):
            raise ValueError(
                f"BasicBlock1d: an identity shortcut needs in_ch == out_ch, stride 1 and 'same' padding; "
                f"got in_ch={in_ch}, out_ch={out_ch}, stride={stride}, padding={padding}, kernel={kernel}"
            )
        self.conv1 = nn.Conv1d(in_ch, out_ch, kernel, stride=stride, padding=padding, bias=False)
        self.bn1 = nn.BatchNorm1d(out_ch)
        self.conv2 = nn.Conv1d(out_ch, out_ch, kernel, padding=kernel // 2, bias=False)
        self.bn2 = nn.BatchNorm1d(out_ch)
        self.act = nn.LeakyReLU(slope)
        self.shortcut: nn.Module = (
            nn.Sequential(
                nn.Conv1d(in_ch, out_ch, kernel, stride=stride, padding=padding, bias=False),
                nn.BatchNorm1d(out_ch),
            )
            if downsample
            else nn.Identity()
        )

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        if self.frames_as_matmul:
            weight = torch.cat([self.conv1.weight, self.shortcut[0].weight])  # (2 out_ch, 1, kernel)
            y, short = frame_conv1d(x, weight, self.conv1.stride[0], self.conv1.padding[0]).chunk(2, dim=1)
            short = self.shortcut[1](short)
        else:
            y, short = self.conv1(x), self.shortcut(x)
        y = self.bn2(self.conv2(self.act(self.bn1(y))))
        return self.act(y + short)


def frame_conv1d(x: torch.Tensor, weight: torch.Tensor, stride: int = 1, padding: int = 0) -> torch.Tensor:
    """``F.conv1d(x, weight, stride=stride, padding=padding)`` of a one-channel signal as one matrix product.

    The padded signal is cut into its ``T`` frames of ``kernel`` samples, ``stride`` apart (a strided view),
    and ``frames @ weight.T`` gives every output channel at every frame. Its weight gradient is one matrix
    product too, ``frames.T @ grad``, where cuDNN's bfloat16 weight gradient of a one-input-channel
    convolution is a slow direct kernel (on an H200: 79 of the 153 ms of CaMN's compiled paper-preset step
    at batch 1024; ``bench/records/bench_train_h200_tune.log``).

    Parameters
    ----------
    x : torch.Tensor
        (B, 1, L) signal.
    weight : torch.Tensor
        (C, 1, kernel) convolution weights (no bias).
    stride, padding : int
        As :func:`torch.nn.functional.conv1d`'s (zero padding on both sides).

    Returns
    -------
    torch.Tensor
        (B, C, T) with T = floor((L + 2 padding - kernel) / stride) + 1.

    Examples
    --------
    >>> x, w = torch.randn(2, 1, 100), torch.randn(4, 1, 15)
    >>> y = frame_conv1d(x, w, stride=5, padding=7)
    >>> y.shape
    torch.Size([2, 4, 20])
    >>> torch.allclose(y, nn.functional.conv1d(x, w, stride=5, padding=7), atol=1e-5)
    True
    """
    if x.ndim != 3 or x.shape[1] != 1 or weight.ndim != 3 or weight.shape[1] != 1:
        raise ValueError(
            f"frame_conv1d: x must be (B, 1, L) and weight (C, 1, kernel); got {tuple(x.shape)}, {tuple(weight.shape)}"
        )
    if stride < 1 or padding < 0:
        raise ValueError(f"frame_conv1d: stride must be >= 1 and padding >= 0; got {stride}, {padding}")
    padded = nn.functional.pad(x[:, 0], (padding, padding))
    frames = padded.unfold(-1, weight.shape[-1], stride)  # (B, T, kernel), a strided view
    return (frames @ weight[:, 0].t()).transpose(1, 2)


def use_frame_matmul(model: nn.Module, on: bool = True) -> int:
    """Switch :attr:`BasicBlock1d.frames_as_matmul` in every block of ``model`` that can take it.

    Parameters
    ----------
    model : torch.nn.Module
        Searched through ``modules()`` (e.g. a CaMN, whose WavEncoder's first block reads the raw waveform).
    on : bool
        The matrix-product route (True) or the convolution kernels (False, the default of every block).

    Returns
    -------
    int
        Blocks switched: those with a one-channel input and a convolutional shortcut.

    Examples
    --------
    >>> use_frame_matmul(WavEncoder((4, 8, 8, 16, 16, 32)))
    1
    """
    blocks = [
        m for m in model.modules()
        if isinstance(m, BasicBlock1d) and m.conv1.in_channels == 1 and not isinstance(m.shortcut, nn.Identity)
    ]  # fmt: skip
    for block in blocks:
        block.frames_as_matmul = bool(on)
    return len(blocks)


class WavEncoder(nn.Module):
    """CaMN's raw-waveform encoder: 6 residual blocks, 16 kHz audio -> 15 fps features.

    Block layout (in, out, kernel, stride, padding; docs/reference_code.md#camn-encoders):
    (1, c0, 15, 5, 1600)*, (c0, c1, 15, 6, 0)*, (c1, c2, 15, 1, 7), (c2, c3, 15, 6, 0)*,
    (c3, c4, 15, 1, 7), (c4, c5, 15, 6, 0)* (* = conv shortcut); the paper widths are
    ``channels = (32, 32, 32, 64, 64, 128)``. The total stride is 5 * 6 * 6 * 6 = 1080
    samples per frame: 36266 samples (34 frames at 15 fps) -> 7891 -> 1313 -> 1313 -> 217
    -> 217 -> 34 frames.

    Parameters
    ----------
    channels : sequence of 6 int
        Output channels of the six blocks; the feature size is ``channels[-1]``.

    Shapes
    ------
    (B, S) float waveform -> (B, T', channels[-1]) with T' = 34 for S = 36266.

    Examples
    --------
    The ``tiny`` CaMN's widths on one 34-frame window of 16 kHz audio:

    >>> import torch
    >>> from beatlite.models.layers import WavEncoder
    >>> _ = torch.manual_seed(0)
    >>> tuple(WavEncoder((4, 8, 8, 16, 16, 32))(torch.zeros(1, 36266)).shape)
    (1, 34, 32)
    """

    def __init__(self, channels: Sequence[int] = (32, 32, 32, 64, 64, 128)) -> None:
        super().__init__()
        c = tuple(int(v) for v in channels)
        if len(c) != 6:
            raise ValueError(f"WavEncoder: channels must have 6 entries, got {c}")
        same_c2 = c[2] == c[1]
        same_c4 = c[4] == c[3]
        self.blocks = nn.Sequential(
            BasicBlock1d(1, c[0], 15, 5, 1600, downsample=True),
            BasicBlock1d(c[0], c[1], 15, 6, 0, downsample=True),
            BasicBlock1d(c[1], c[2], 15, 1, 7, downsample=not same_c2),
            BasicBlock1d(c[2], c[3], 15, 6, 0, downsample=True),
            BasicBlock1d(c[3], c[4], 15, 1, 7, downsample=not same_c4),
            BasicBlock1d(c[4], c[5], 15, 6, 0, downsample=True),
        )
        self.out_features = c[5]

    def forward(self, audio: torch.Tensor) -> torch.Tensor:
        if audio.ndim != 2:
            raise ValueError(f"WavEncoder: audio must be (B, S), got shape {tuple(audio.shape)}")
        return self.blocks(audio.unsqueeze(1)).transpose(1, 2)


class PlainWavEncoder(nn.Module):
    """Trimodal's waveform encoder: 4 plain convolutions (docs/reference_code.md#trimodal), 36266 samples -> 34 frames.

    ``Conv1d(1, c0, 15, stride 5, padding 1600) -> BN -> LReLU(0.3)``, then three
    ``Conv1d(k15, stride 6)`` layers (the last without BN/activation); reference widths
    ``channels = (16, 32, 64, 32)``.

    Shapes
    ------
    (B, S) float waveform, 16 kHz -> (B, T', channels[-1]); S = 36266 samples give
    ``(36266 + 3200 - 15) // 5 + 1 = 7891 -> 1313 -> 217 -> 34`` frames.

    Examples
    --------
    >>> import torch
    >>> from beatlite.models.layers import PlainWavEncoder
    >>> _ = torch.manual_seed(0)
    >>> tuple(PlainWavEncoder()(torch.zeros(1, 36266)).shape)
    (1, 34, 32)
    """

    def __init__(self, channels: Sequence[int] = (16, 32, 64, 32)) -> None:
        super().__init__()
        c = tuple(int(v) for v in channels)
        if len(c) != 4:
            raise ValueError(f"PlainWavEncoder: channels must have 4 entries, got {c}")
        self.net = nn.Sequential(
            nn.Conv1d(1, c[0], 15, stride=5, padding=1600),
            nn.BatchNorm1d(c[0]),
            nn.LeakyReLU(0.3),
            nn.Conv1d(c[0], c[1], 15, stride=6),
            nn.BatchNorm1d(c[1]),
            nn.LeakyReLU(0.3),
            nn.Conv1d(c[1], c[2], 15, stride=6),
            nn.BatchNorm1d(c[2]),
            nn.LeakyReLU(0.3),
            nn.Conv1d(c[2], c[3], 15, stride=6),
        )
        self.out_features = c[3]

    def forward(self, audio: torch.Tensor) -> torch.Tensor:
        if audio.ndim != 2:
            raise ValueError(f"PlainWavEncoder: audio must be (B, S), got shape {tuple(audio.shape)}")
        return self.net(audio.unsqueeze(1)).transpose(1, 2)


class _TemporalBlock(nn.Module):
    """Two weight-normalised causal dilated convolutions with a residual connection."""

    def __init__(self, in_ch: int, out_ch: int, kernel: int, dilation: int, dropout: float) -> None:
        super().__init__()
        pad = (kernel - 1) * dilation
        self.pad = pad
        self.conv1 = weight_norm(nn.Conv1d(in_ch, out_ch, kernel, padding=pad, dilation=dilation))
        self.conv2 = weight_norm(nn.Conv1d(out_ch, out_ch, kernel, padding=pad, dilation=dilation))
        self.drop = nn.Dropout(dropout)
        self.relu = nn.ReLU()
        self.down = nn.Conv1d(in_ch, out_ch, 1) if in_ch != out_ch else nn.Identity()

    def _causal(self, y: torch.Tensor) -> torch.Tensor:
        return y[:, :, : -self.pad] if self.pad else y

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        y = self.drop(self.relu(self._causal(self.conv1(x))))
        y = self.drop(self.relu(self._causal(self.conv2(y))))
        return self.relu(y + self.down(x))


class TextEncoderTCN(nn.Module):
    """Word-id sequence -> per-frame text features (Trimodal/CaMN ``TextEncoderTCN``).

    ``Embedding(vocab, word_dim) -> Dropout(0.1) -> TCN(n_layers levels of hidden channels,
    kernel 2, dilations 1, 2, 4, ..., weight norm, causal) -> Linear(hidden, out_features)``.

    Parameters
    ----------
    vocab_size, word_dim : int
        Embedding table size (id 0 = PAD). Load pretrained vectors with :meth:`beatlite.models.base.GestureModel.set_word_vectors`.
    hidden, n_layers : int
        TCN width and depth.
    out_features : int
        Feature size per frame.
    dropout : float
        Dropout inside the TCN (reference 0.3).

    Shapes
    ------
    (B, T) int64 word ids in ``0..vocab_size-1`` -> (B, T, out_features)

    Examples
    --------
    The TCN is causal: a frame's features read its word and the earlier ones, so changing the last word
    changes only the last frame.

    >>> import torch
    >>> from beatlite.models.layers import TextEncoderTCN
    >>> _ = torch.manual_seed(0)
    >>> encoder = TextEncoderTCN(20, 8, hidden=16, n_layers=2, out_features=4, dropout=0.0).eval()
    >>> words = torch.tensor([[3, 5, 7, 9, 11]])
    >>> changed = words.clone()
    >>> changed[0, -1] = 2
    >>> a, b = encoder(words), encoder(changed)
    >>> tuple(a.shape), torch.equal(a[:, :-1], b[:, :-1]), torch.equal(a[:, -1], b[:, -1])
    ((1, 5, 4), True, False)
    """

    def __init__(
        self, vocab_size: int, word_dim: int, hidden: int, n_layers: int, out_features: int, dropout: float
    ) -> None:
        super().__init__()
        self.embedding = nn.Embedding(vocab_size, word_dim)
        self.emb_drop = nn.Dropout(0.1)
        layers = []
        for i in range(n_layers):
            layers.append(_TemporalBlock(word_dim if i == 0 else hidden, hidden, 2, 2**i, dropout))
        self.tcn = nn.Sequential(*layers)
        self.proj = nn.Linear(hidden, out_features)
        self.out_features = out_features

    def forward(self, words: torch.Tensor) -> torch.Tensor:
        if words.ndim != 2:
            raise ValueError(f"TextEncoderTCN: words must be (B, T), got shape {tuple(words.shape)}")
        check_ids(words, self.embedding.num_embeddings, "TextEncoderTCN: word ids")
        x = self.emb_drop(self.embedding(words)).transpose(1, 2)
        return self.proj(self.tcn(x).transpose(1, 2))


class ConvDiscriminator(nn.Module):
    """The CaMN/Trimodal sequence discriminator, with the reference's crash fixed.

    ``Conv1d(D, 16, 3) -> BN -> LReLU(0.1) -> Conv1d(16, 8, 3) -> BN -> LReLU -> Conv1d(8, 8, 3)``
    (T -> T - 6 frames), a bidirectional LSTM (``rnn="gru"``: HA2G's GRU) whose two directions are summed
    (the reference passed an undefined ``decoder_hidden``; here the LSTM starts from
    zeros), ``Linear(hidden, 1)`` per frame and ``Linear(T - 6, 1)`` over time.

    Returns a **logit**; ``sigmoid(logit)`` is the reference's probability. The NS-GAN
    losses use ``logsigmoid`` of the logit, which equals ``log(sigmoid)`` but never
    produces ``log(0)``.

    Shapes
    ------
    (B, T, D) -> (B, 1) logits; ``n_frames`` = T must be given at construction.

    Examples
    --------
    >>> import torch
    >>> from beatlite.models.layers import ConvDiscriminator
    >>> _ = torch.manual_seed(0)
    >>> d = ConvDiscriminator(141, hidden=16, n_layers=1, n_frames=34)
    >>> tuple(d(torch.zeros(3, 34, 141)).shape)
    (3, 1)
    """

    def __init__(
        self,
        input_dim: int,
        *,
        hidden: int = 64,
        n_layers: int = 4,
        n_frames: int = WINDOW_LENGTH,
        slope: float = 0.1,
        rnn: str = "lstm",
    ) -> None:
        super().__init__()
        if n_frames < 7:
            raise ValueError(f"{type(self).__name__}: n_frames must be >= 7, got {n_frames}")
        if rnn not in ("lstm", "gru"):
            raise ValueError(f"{type(self).__name__}: rnn must be 'lstm' or 'gru', got {rnn!r}")
        self.convs = nn.Sequential(
            nn.Conv1d(input_dim, 16, 3),
            nn.BatchNorm1d(16),
            nn.LeakyReLU(slope),
            nn.Conv1d(16, 8, 3),
            nn.BatchNorm1d(8),
            nn.LeakyReLU(slope),
            nn.Conv1d(8, 8, 3),
        )
        self.hidden = hidden
        self.rnn_name = rnn
        layer = nn.LSTM if rnn == "lstm" else nn.GRU
        # registered as ``lstm`` or ``gru``: the state-dict keys of the shipped checkpoints
        setattr(
            self,
            rnn,
            layer(
                8,
                hidden,
                num_layers=n_layers,
                bidirectional=True,
                batch_first=True,
                dropout=0.3 if n_layers > 1 else 0,
            ),
        )
        self.out = nn.Linear(hidden, 1)
        self.out2 = nn.Linear(n_frames - 6, 1)
        self.n_frames = n_frames
        self.input_dim = input_dim

    def forward(self, pose: torch.Tensor) -> torch.Tensor:
        if pose.ndim != 3 or pose.shape[1] != self.n_frames or pose.shape[2] != self.input_dim:
            raise ValueError(
                f"{type(self).__name__}: pose must be (B, {self.n_frames}, {self.input_dim}), "
                f"got shape {tuple(pose.shape)}"
            )
        feat = self.convs(pose.transpose(1, 2)).transpose(1, 2)
        rnn = getattr(self, self.rnn_name)
        seq = run_lstm(rnn, feat) if self.rnn_name == "lstm" else rnn(feat)[0]
        return self.out2(self.out(sum_directions(seq, self.hidden)).squeeze(-1))


def check_ids(ids: torch.Tensor, n: int, what: str) -> None:
    """Raise ``ValueError`` naming ``what`` unless every id of ``ids`` is in ``[0, n)``.

    Not checked in a training step on a GPU (ids on another device than the CPU, gradients on): reading
    their range would copy it to the host and make the host wait for the device at every step (no step
    could then be queued ahead or captured in a CUDA graph); there the embedding's own device-side bounds
    check stops a bad id (a CUDA error, never a wrong answer), as the CPU embedding's own check (an
    ``IndexError``) does inside a ``torch.compile``-d pass. The windows a model trains on are in range by
    construction (the store's vocabulary and speaker ids); generation and evaluation (no gradients) check.

    Shapes: ids any shape, integer.

    Examples
    --------
    >>> import torch
    >>> from beatlite.models.layers import check_ids
    >>> check_ids(torch.tensor([0, 4]), 5, "speaker ids")  # in range: nothing
    >>> check_ids(torch.tensor([4, 5]), 5, "speaker ids")
    Traceback (most recent call last):
    ...
    ValueError: speaker ids must be in [0, 5), got range [4, 5]
    """
    training_on_device = ids.device.type != "cpu" and torch.is_grad_enabled()
    if not ids.numel() or training_on_device or torch.compiler.is_compiling():
        return
    low, high = int(ids.min()), int(ids.max())
    if low < 0 or high >= n:
        raise ValueError(f"{what} must be in [0, {n}), got range [{low}, {high}]")


def mlp(sizes: Sequence[int], slope: float = 0.1, *, last_act: bool = True) -> nn.Sequential:
    """``Linear -> LeakyReLU(slope)`` for each consecutive pair of ``sizes`` (no act after the last if asked).

    Shapes: (..., sizes[0]) -> (..., sizes[-1]).

    Examples
    --------
    >>> from beatlite.models.layers import mlp
    >>> [type(layer).__name__ for layer in mlp([4, 8, 2], last_act=False)]
    ['Linear', 'LeakyReLU', 'Linear']
    """
    layers: list[nn.Module] = []
    for i in range(len(sizes) - 1):
        layers.append(nn.Linear(sizes[i], sizes[i + 1]))
        if last_act or i < len(sizes) - 2:
            layers.append(nn.LeakyReLU(slope))
    return nn.Sequential(*layers)


def run_lstm(lstm: nn.LSTM, x: torch.Tensor) -> torch.Tensor:
    """``lstm(x)``'s output sequence, also under CPU bf16 autocast on a CPU without a bf16 LSTM kernel.

    CPU autocast sends an LSTM to oneDNN in bfloat16, and on x86 CPUs without AVX-512 (e.g. AMD Zen 3, where
    ``torch.backends.cpu.get_cpu_capability()`` is ``"AVX2"``) torch 2.13 then raises "could not create a
    primitive descriptor for the LSTM forward propagation primitive". There the LSTM runs in float32 with
    autocast off, as CPU autocast already runs every GRU; everywhere else (CUDA, CPUs with the kernel, no
    autocast) it is ``lstm(x)[0]`` unchanged. So a bf16 training step on such a CPU computes the LSTM more
    exactly than on a CPU with the kernel: one of the differences between machines.

    Shapes: x ``(B, T, input_size)`` (``batch_first``) -> ``(B, T, D * hidden_size)``, D = 2 if bidirectional.

    Examples
    --------
    >>> lstm = nn.LSTM(3, 4, batch_first=True, bidirectional=True)
    >>> with torch.autocast("cpu", dtype=torch.bfloat16):
    ...     y = run_lstm(lstm, torch.zeros(2, 5, 3))
    >>> tuple(y.shape)
    (2, 5, 8)
    """
    if x.device.type == "cpu" and torch.is_autocast_enabled("cpu") and not _cpu_autocast_lstm_works():
        with torch.autocast("cpu", enabled=False):
            return lstm(x.float())[0]
    return lstm(x)[0]


@functools.cache
def _cpu_autocast_lstm_works() -> bool:
    """Whether an LSTM runs under CPU bf16 autocast here (tried once on a 1-unit LSTM; the global random
    state is left as it was)."""
    with torch.random.fork_rng(devices=[]), torch.no_grad(), torch.autocast("cpu", dtype=torch.bfloat16):
        try:
            nn.LSTM(1, 1, batch_first=True)(torch.zeros(1, 1, 1))
        except RuntimeError:
            return False
    return True


def sum_directions(seq: torch.Tensor, hidden: int) -> torch.Tensor:
    """Sum the forward and backward halves of a bidirectional RNN output ``(B, T, 2H) -> (B, T, H)``.

    Examples
    --------
    >>> import torch
    >>> from beatlite.models.layers import sum_directions
    >>> sum_directions(torch.tensor([[[1.0, 2.0, 10.0, 20.0]]]), 2)
    tensor([[[11., 22.]]])
    """
    return seq[..., :hidden] + seq[..., hidden:]


def match_length(x: torch.Tensor, n: int) -> torch.Tensor:
    """Crop or repeat-last-frame pad ``(B, T, C)`` to ``(B, n, C)`` (the reference's length fix-ups).

    Examples
    --------
    >>> import torch
    >>> from beatlite.models.layers import match_length
    >>> x = torch.tensor([1.0, 2.0, 3.0]).reshape(1, 3, 1)
    >>> match_length(x, 5).flatten().tolist(), match_length(x, 2).flatten().tolist()
    ([1.0, 2.0, 3.0, 3.0, 3.0], [1.0, 2.0])
    """
    t = x.shape[1]
    if t == n:
        return x
    if t > n:
        return x[:, :n]
    if t == 0:
        raise ValueError("match_length: cannot pad an empty sequence")
    return torch.cat([x, x[:, -1:].expand(-1, n - t, -1)], dim=1)


def ns_gan_d_loss(real_logit: torch.Tensor, fake_logit: torch.Tensor) -> torch.Tensor:
    """Discriminator NS-GAN loss ``-mean(log D(real) + log(1 - D(fake)))`` from logits.

    Parameters
    ----------
    real_logit, fake_logit : (B, 1) float tensors
        The discriminator's logits (``D = sigmoid(logit)``) of real and generated windows.

    Returns
    -------
    scalar tensor, nats.

    Examples
    --------
    An undecided discriminator (logits 0, D = 1/2) pays ``2 log 2``:

    >>> import torch
    >>> from beatlite.models.layers import ns_gan_d_loss
    >>> round(float(ns_gan_d_loss(torch.zeros(4, 1), torch.zeros(4, 1))), 4)
    1.3863
    """
    return -(nn.functional.logsigmoid(real_logit) + nn.functional.logsigmoid(-fake_logit)).mean()


def ns_gan_g_loss(fake_logit: torch.Tensor) -> torch.Tensor:
    """Generator non-saturating loss ``-mean(log D(fake))`` from logits.

    Parameters
    ----------
    fake_logit : (B, 1) float tensor
        The discriminator's logits of generated windows.

    Returns
    -------
    scalar tensor, nats.

    Examples
    --------
    ``log 2`` when D = 1/2; about 0 once the discriminator takes the fakes for real (logit 10):

    >>> import torch
    >>> from beatlite.models.layers import ns_gan_g_loss
    >>> round(float(ns_gan_g_loss(torch.zeros(4, 1))), 4), round(float(ns_gan_g_loss(torch.full((4, 1), 10.0))), 4)
    (0.6931, 0.0)
    """
    return -nn.functional.logsigmoid(fake_logit).mean()


def kl_standard_normal(mu: torch.Tensor, logvar: torch.Tensor) -> torch.Tensor:
    """Mean over elements of KL(N(mu, exp(logvar)) || N(0, 1)) = ``-0.5 (1 + logvar - mu^2 - exp(logvar))``: the
    KL term of every model with a sampled Gaussian code (A2G, HA2G's style, Trimodal's speaker style).

    Parameters
    ----------
    mu, logvar : (...) float tensors of one shape
        Means and natural-log variances of independent Gaussians.

    Returns
    -------
    () float tensor, nats per element.

    Examples
    --------
    N(1, 1) is 0.5 nat from N(0, 1) (``mu^2 / 2``); N(0, e) is ``(e - 1 - 1) / 2 = 0.3591`` nat; the mean of
    the two:

    >>> import math, torch
    >>> from beatlite.models.layers import kl_standard_normal
    >>> round(float(kl_standard_normal(torch.tensor([1.0, 0.0]), torch.tensor([0.0, 1.0]))), 4)
    0.4296
    >>> round((0.5 + (math.e - 2) / 2) / 2, 4)
    0.4296
    """
    if mu.shape != logvar.shape:
        raise ValueError(f"mu {tuple(mu.shape)} and logvar {tuple(logvar.shape)} must have one shape")
    return -0.5 * torch.mean(1 + logvar - mu.pow(2) - logvar.exp())


def reparameterize(mu: torch.Tensor, logvar: torch.Tensor, noise: torch.Tensor) -> torch.Tensor:
    """``mu + exp(logvar / 2) * noise``: a draw of N(mu, exp(logvar)) that is differentiable in mu, logvar (each
    model draws ``noise`` its own way: its generators and dtypes fix its numbers).

    Parameters
    ----------
    mu, logvar : (...) float tensors
        Means and log-variances.
    noise : (...) float tensor of their shape
        Standard-normal draws.

    Returns
    -------
    (...) float tensor, in the units of ``mu``.

    Examples
    --------
    Variance 4 (standard deviation 2) around 1: noise 0 gives the mean, noise 1.5 gives ``1 + 2 * 1.5``.

    >>> import math, torch
    >>> from beatlite.models.layers import reparameterize
    >>> reparameterize(torch.ones(2), torch.full((2,), math.log(4.0)), torch.tensor([0.0, 1.5]))
    tensor([1., 4.])
    """
    return mu + torch.exp(0.5 * logvar) * noise
