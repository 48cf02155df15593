"""Random window batches with the shapes of :func:`beatlite.data.windows.build_windows`, for tests.

The values are random (seeded) but respect each key's type and range, so a
model's forward/backward pass can be unit-tested without the data pipeline.

Not taught in a notebook: fake windows and batches for the tests.
"""

from __future__ import annotations

import numpy as np
import torch

FAKE_SHAPES: dict[str, tuple[int, ...]] = {
    "pose": (34, 141),
    "dirvec": (34, 126),
    "audio": (36266,),
    "mel": (70, 128),
    "face": (34, 51),
    "word": (34,),
    "emotion": (34,),
    "semantic": (34,),
    "speaker": (),
}
"""Per-window shape of each key (the batch adds a leading B)."""


def fake_windows(
    n: int, *, seed: int = 0, vocab_size: int = 100, n_speakers: int = 4, n_frames: int = 34
) -> dict[str, np.ndarray]:
    """A numpy window dict of ``n`` random windows (the layout of ``build_windows``).

    Parameters
    ----------
    n : int
        Number of windows N.
    seed : int
        Seed of the numpy generator.
    vocab_size, n_speakers : int
        Ranges of ``"word"`` ids (``0..vocab_size-1``) and ``"speaker"`` ids.
    n_frames : int
        Frames T per window (34 by default; audio gets ``floor(T / 15 * 16000)`` samples,
        mel ``round((T / 15 * 16000 - 1024) / 512 + 1)`` frames).

    Returns
    -------
    dict of str -> ndarray
        ``"pose"`` (N, T, 141) float32 ~N(0, 1); ``"dirvec"`` (N, T, 126) float32 small;
        ``"audio"`` (N, S) float32 in [-1, 1]; ``"mel"`` (N, M, 128) float32 in [-80, 0] dB;
        ``"face"`` (N, T, 51) float32 in [0, 1]; ``"word"`` (N, T) int64; ``"emotion"`` (N, T) int64
        in 0..7; ``"semantic"`` (N, T) float32 in [0, 1]; ``"speaker"`` (N,) int64.
    """
    if n < 1 or n_frames < 1:
        raise ValueError(f"n and n_frames must be >= 1, got n={n}, n_frames={n_frames}")
    rng = np.random.default_rng(seed)
    t = n_frames
    n_audio = int(np.floor(t / 15 * 16000))
    n_mel = int(round((t / 15 * 16000 - 1024) / 512 + 1))
    emotion = np.repeat(rng.integers(0, 8, size=(n, 1)), t, axis=1).astype(np.int64)
    return {
        "pose": rng.standard_normal((n, t, 141)).astype(np.float32),
        "dirvec": (0.3 * rng.standard_normal((n, t, 126))).astype(np.float32),
        "audio": rng.uniform(-0.5, 0.5, size=(n, n_audio)).astype(np.float32),
        "mel": rng.uniform(-80.0, 0.0, size=(n, n_mel, 128)).astype(np.float32),
        "face": rng.uniform(0.0, 1.0, size=(n, t, 51)).astype(np.float32),
        "word": rng.integers(0, vocab_size, size=(n, t)).astype(np.int64),
        "emotion": emotion,
        "semantic": rng.uniform(0.0, 1.0, size=(n, t)).astype(np.float32),
        "speaker": rng.integers(0, n_speakers, size=n).astype(np.int64),
    }


def fake_batch(b: int = 2, *, seed: int = 0, **kwargs: int) -> dict[str, torch.Tensor]:
    """:func:`fake_windows` as a dict of torch tensors (float32 / int64), batch size ``b``."""
    return {k: torch.from_numpy(v) for k, v in fake_windows(b, seed=seed, **kwargs).items()}
