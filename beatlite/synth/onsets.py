"""Acoustic onsets of the generated speech: where the motion beats are placed.

A small, self-contained spectral-flux detector (numpy only, so the corpus does not depend on
librosa's version or its JIT start-up) with librosa's default settings and time convention:
log-mel power spectrogram (2048-sample centred frames, hop 512, 128 bands, 80 dB range),
positive frame-to-frame flux averaged over the bands, reported ``n_fft // (2 hop)`` frames late
as ``librosa.onset.onset_strength(center=True)`` does; then the peak picking of
:func:`beatlite.metrics.beats.audio_beats` (maximum within ±3 frames = ±96 ms, above the
±100 ms mean by 0.07 of the normalised envelope, at least 3 frames after the previous onset).
It finds the events ``librosa.onset.onset_detect`` (and so BeatAlign and BC) finds, to within a
frame: the onsets of words and of stressed syllables.

Part of the corpus generator :mod:`beatlite.synth`, which no notebook teaches (``data_samples/README.md`` describes its rules).
"""

from __future__ import annotations

import numpy as np

HOP = 512
"""Analysis hop, samples (32 ms at 16 kHz; librosa's default)."""
N_FFT = 2048
"""Analysis window, samples (librosa's default)."""
N_MELS = 128
"""Mel bands."""


def _mel_filters(sr: int, n_fft: int, n_mels: int) -> np.ndarray:
    """Triangular mel filterbank (HTK mel scale), (n_mels, n_fft // 2 + 1) float64."""
    mel = np.linspace(0.0, 2595.0 * np.log10(1.0 + (sr / 2) / 700.0), n_mels + 2)
    hz = 700.0 * (10.0 ** (mel / 2595.0) - 1.0)
    freqs = np.linspace(0.0, sr / 2, n_fft // 2 + 1)
    lo, mid, hi = hz[:-2, None], hz[1:-1, None], hz[2:, None]
    up = (freqs[None, :] - lo) / (mid - lo)
    down = (hi - freqs[None, :]) / (hi - mid)
    return np.maximum(0.0, np.minimum(up, down))


def onset_envelope(audio: np.ndarray, sr: int) -> np.ndarray:
    """Onset strength: mean positive log-mel flux per frame.

    Parameters
    ----------
    audio : (N,) float
        Mono waveform in [-1, 1].
    sr : int
        Sample rate, Hz.

    Returns
    -------
    (F,) float64
        Frame ``f`` is the rise into the frame centred on sample ``f * HOP``; ``env[0] = 0``.

    Examples
    --------
    One second at 16 kHz has ``1 + 16000 // 512 = 32`` centred frames; a noise burst starting at
    sample 8000 first enters the 2048-sample window of frame 14 (centred on 7168, reaching 8192).

    >>> y = np.zeros(16000)
    >>> y[8000:9600] = 0.5 * np.random.default_rng(0).normal(size=1600)
    >>> env = onset_envelope(y, 16000)
    >>> env.shape, float(env[0]), int(env.argmax())
    ((32,), 0.0, 14)
    """
    y = np.asarray(audio, dtype=np.float64)
    if y.ndim != 1:
        raise ValueError(f"onset_envelope: audio must be 1-D, got shape {y.shape}")
    if y.size < 2:
        return np.zeros(max(y.size, 1))
    pad = np.pad(y, N_FFT // 2)
    n_frames = 1 + (pad.size - N_FFT) // HOP if pad.size >= N_FFT else 1
    if pad.size < N_FFT:
        pad = np.pad(pad, (0, N_FFT - pad.size))
    idx = np.arange(N_FFT)[None, :] + HOP * np.arange(n_frames)[:, None]
    frames = pad[idx] * np.hanning(N_FFT)[None, :]
    power = np.abs(np.fft.rfft(frames, axis=1)) ** 2
    mel = power @ _mel_filters(int(sr), N_FFT, N_MELS).T
    db = 10.0 * np.log10(np.maximum(mel, 1e-10))
    db = np.maximum(db, db.max() - 80.0)
    env = np.zeros(n_frames)
    env[1:] = np.maximum(0.0, np.diff(db, axis=0)).mean(axis=1)
    return env


def speech_onsets(audio: np.ndarray, sr: int, *, delta: float = 0.07) -> np.ndarray:
    """Onset times of a speech waveform, seconds.

    Parameters
    ----------
    audio : (N,) float
        Mono waveform in [-1, 1].
    sr : int
        Sample rate, Hz.
    delta : float
        Threshold above the local mean, on the envelope normalised to [0, 1].

    Returns
    -------
    (K,) float64
        Increasing onset times, seconds (librosa's convention: the flux frame + ``N_FFT // (2 HOP)``).

    Examples
    --------
    Three 0.1-s noise bursts at 0.5, 1.3 and 2.1 s are found on the 32-ms hop grid, within 1.5 hops of
    their starts (e.g. frame 14 + 2 = 16 hops = 0.512 s).

    >>> sr, rng = 16000, np.random.default_rng(0)
    >>> y = np.zeros(3 * sr)
    >>> for start in (0.5, 1.3, 2.1):
    ...     y[int(start * sr) : int(start * sr) + 1600] = 0.5 * rng.normal(size=1600)
    >>> np.round(speech_onsets(y, sr), 3).tolist()
    [0.512, 1.312, 2.112]
    """
    env = onset_envelope(audio, sr)
    if env.size < 3 or env.max() <= env.min():
        return np.zeros(0)
    env = (env - env.min()) / (env.max() - env.min())
    k = max(int(round(0.1 * sr / HOP)), 1)
    padded = np.pad(env, k + 1, mode="edge")
    windows = np.lib.stride_tricks.sliding_window_view(padded, 2 * k + 3)  # centre at index k + 1
    local_max = windows[:, 1 : 2 * k + 2].max(axis=1)
    local_mean = windows[:, 1:].mean(axis=1)
    candidates = np.flatnonzero((env >= local_max) & (env >= local_mean + delta))
    picked: list[int] = []
    for f in candidates:
        if not picked or f - picked[-1] > k:
            picked.append(int(f))
    lag = N_FFT // (2 * HOP)
    return (np.asarray(picked, dtype=np.float64) + lag) * HOP / sr
