"""ARKit blendshape weights (51, 60 fps) driven by the audio, the phones and the emotion.

- Mouth: ``jawOpen``, ``mouthLowerDown*`` follow the audio RMS envelope; ``mouthClose`` and
  ``mouthPress*`` rise on bilabial phones (p, b, m), ``mouthFunnel``/``mouthPucker`` on rounded
  vowels and w, ``mouthStretch*`` on spread vowels.
- Expression: each emotion adds a fixed profile (:data:`EMOTION_FACES`), cross-faded over 0.5 s
  where the emotion changes.
- Eyes: blinks (``eyeBlinkLeft/Right`` to ~0.95 for 0.15 s) every 3-5 s, slow gaze drift.

Part of the corpus generator :mod:`beatlite.synth`, which no notebook teaches (``data_samples/README.md`` describes its rules).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

EMOTION_FACES: dict[int, dict[str, float]] = {
    0: {},
    1: {"mouthSmileLeft": 0.6, "mouthSmileRight": 0.6, "cheekSquintLeft": 0.35, "cheekSquintRight": 0.35,
        "eyeSquintLeft": 0.2, "eyeSquintRight": 0.2},
    2: {"browDownLeft": 0.7, "browDownRight": 0.7, "eyeSquintLeft": 0.3, "eyeSquintRight": 0.3,
        "noseSneerLeft": 0.2, "noseSneerRight": 0.2, "mouthPressLeft": 0.2, "mouthPressRight": 0.2,
        "jawForward": 0.1},
    3: {"browInnerUp": 0.6, "mouthFrownLeft": 0.5, "mouthFrownRight": 0.5, "eyeLookDownLeft": 0.2,
        "eyeLookDownRight": 0.2, "mouthShrugLower": 0.2},
    4: {"mouthSmileLeft": 0.35, "mouthDimpleLeft": 0.3, "eyeSquintLeft": 0.15, "browOuterUpRight": 0.2},
    5: {"browInnerUp": 0.7, "browOuterUpLeft": 0.7, "browOuterUpRight": 0.7, "eyeWideLeft": 0.6,
        "eyeWideRight": 0.6, "jawOpen": 0.15},
    6: {"browInnerUp": 0.6, "eyeWideLeft": 0.5, "eyeWideRight": 0.5, "mouthStretchLeft": 0.4,
        "mouthStretchRight": 0.4, "browDownLeft": 0.1, "browDownRight": 0.1},
    7: {"noseSneerLeft": 0.6, "noseSneerRight": 0.6, "mouthUpperUpLeft": 0.4, "mouthUpperUpRight": 0.4,
        "browDownLeft": 0.3, "browDownRight": 0.3, "cheekSquintLeft": 0.2, "cheekSquintRight": 0.2},
}  # fmt: skip
"""Emotion id -> blendshape offsets added to the neutral face."""

_BILABIAL = {"p", "b", "m"}
_ROUNDED = {"u:", "U", "oU", "O:", "O", "w", "aU", "OI", "U@", "O@", "o@", "0"}
_SPREAD = {"i:", "i", "eI", "I", "E", "e@", "i@"}


def _smooth(x: np.ndarray, width: int) -> np.ndarray:
    kernel = np.hanning(2 * width + 1)
    kernel /= kernel.sum()
    pad = np.pad(x, [(width, width)] + [(0, 0)] * (x.ndim - 1), mode="edge")
    if x.ndim == 1:
        return np.convolve(pad, kernel, mode="valid")
    return np.stack([np.convolve(pad[:, k], kernel, mode="valid") for k in range(x.shape[1])], axis=1)


def face_weights(
    names: Sequence[str],
    n_frames: int,
    fps: float,
    audio: np.ndarray,
    sr: int,
    phones: Sequence[tuple[float, float, str]],
    emotion: np.ndarray,
    rng: np.random.Generator,
) -> np.ndarray:
    """Blendshape weights of a take.

    Parameters
    ----------
    names : sequence of str, length K
        Blendshape names (ARKit, 51 for BEAT).
    n_frames : int
        Number of face frames T.
    fps : float
        Face frame rate (60 in BEAT).
    audio : (N,) float
        Waveform in [-1, 1].
    sr : int
        Audio rate, Hz.
    phones : sequence of (start, end, phone)
        Timed phones, seconds.
    emotion : (T,) int
        Emotion id of each face frame.
    rng : numpy.random.Generator

    Returns
    -------
    (T, K) float64 in [0, 1], rounded to 3 decimals.

    Examples
    --------
    One silent second of happiness: the jaw stays shut, the smile holds its profile value 0.6
    (:data:`EMOTION_FACES`); an "m" from 0.2 to 0.5 s closes the lips (``mouthClose`` 0.3) in a
    neutral second.

    >>> from beatlite.io.facial import ARKIT_51
    >>> def column(w, name):
    ...     return w[:, ARKIT_51.index(name)]
    >>> silence = np.zeros(16000)
    >>> w = face_weights(ARKIT_51, 60, 60, silence, 16000, [], np.ones(60, int), np.random.default_rng(0))
    >>> w.shape, float(column(w, "jawOpen").max()), set(column(w, "mouthSmileLeft").tolist())
    ((60, 51), 0.0, {0.6})
    >>> w = face_weights(ARKIT_51, 60, 60, silence, 16000, [(0.2, 0.5, "m")], np.zeros(60, int),
    ...                  np.random.default_rng(0))
    >>> close = column(w, "mouthClose")  # frames 12-29 are the "m" (0.2-0.5 s at 60 fps)
    >>> float(close[:6].max()), float(close[21]), float(close[45])
    (0.0, 0.3, 0.0)
    """
    index = {n: k for k, n in enumerate(names)}
    emotion = np.asarray(emotion)
    if emotion.shape != (n_frames,):
        raise ValueError(f"face_weights: emotion must be ({n_frames},), got shape {emotion.shape}")
    t = np.arange(n_frames) / fps
    w = np.zeros((n_frames, len(names)))
    env = _audio_envelope(audio, sr, t)
    _add_mouth(w, index, t, env, phones)
    # emotion expression, cross-faded
    profile = np.zeros((8, len(names)))
    for e, shapes in EMOTION_FACES.items():
        for name, value in shapes.items():
            if name in index:
                profile[e, index[name]] = value
    w += _smooth(profile[emotion], int(0.25 * fps))
    _add_eyes(w, index, t, rng)
    return np.round(np.clip(w, 0.0, 1.0), 3)


def _add(w: np.ndarray, index: dict[str, int], name: str, value: np.ndarray | float) -> None:
    """Add ``value`` to column ``name`` of the weights ``w`` (T, K) (nothing when it is not a column)."""
    if name in index:
        w[:, index[name]] += value


def _audio_envelope(audio: np.ndarray, sr: int, t: np.ndarray) -> np.ndarray:
    """Mouth-opening envelope: audio RMS over +-12.5 ms around each frame time.

    Parameters
    ----------
    audio : (N,) float
        Waveform in [-1, 1].
    sr : int
        Audio rate, Hz.
    t : (T,) float
        Frame times, seconds.

    Returns
    -------
    (T,) float64 in [0, 1.2]: the RMS over its 95th percentile, clipped and lightly smoothed.
    """
    y = np.asarray(audio, dtype=np.float64)
    centres = np.clip(np.round(t * sr).astype(np.int64), 0, max(y.size - 1, 0))
    half = int(0.0125 * sr)
    csum = np.concatenate([[0.0], np.cumsum(y**2)])
    lo = np.clip(centres - half, 0, y.size)
    hi = np.clip(centres + half, 0, y.size)
    rms = np.sqrt((csum[hi] - csum[lo]) / np.maximum(hi - lo, 1))
    ref = np.percentile(rms, 95) if rms.size and np.percentile(rms, 95) > 0 else 1.0
    return _smooth(np.clip(rms / ref, 0, 1.2), 2)


def _add_mouth(
    w: np.ndarray,
    index: dict[str, int],
    t: np.ndarray,
    env: np.ndarray,
    phones: Sequence[tuple[float, float, str]],
) -> None:
    """Jaw and lips: opening by the audio envelope ``env`` (T,), visemes from the timed phones."""
    _add(w, index, "jawOpen", 0.45 * env**0.8)
    _add(w, index, "mouthLowerDownLeft", 0.25 * env)
    _add(w, index, "mouthLowerDownRight", 0.25 * env)
    lab = np.zeros(t.size)
    rnd = np.zeros(t.size)
    spr = np.zeros(t.size)
    for start, end, ph in phones:
        sel = (t >= start) & (t < end)
        lab[sel] += ph in _BILABIAL
        rnd[sel] += ph in _ROUNDED
        spr[sel] += ph in _SPREAD
    lab, rnd, spr = _smooth(lab, 2), _smooth(rnd, 3), _smooth(spr, 3)
    _add(w, index, "mouthClose", 0.3 * lab)
    _add(w, index, "mouthPressLeft", 0.2 * lab)
    _add(w, index, "mouthPressRight", 0.2 * lab)
    _add(w, index, "jawOpen", -0.3 * lab * env)
    _add(w, index, "mouthFunnel", 0.4 * rnd)
    _add(w, index, "mouthPucker", 0.3 * rnd)
    _add(w, index, "mouthStretchLeft", 0.2 * spr)
    _add(w, index, "mouthStretchRight", 0.2 * spr)


def _add_eyes(w: np.ndarray, index: dict[str, int], t: np.ndarray, rng: np.random.Generator) -> None:
    """Blinks every 3-5 s (0.15 s long) and a slow gaze drift, at frame times ``t`` (T,) seconds."""
    blink = np.zeros(t.size)
    tb = rng.uniform(0.5, 3.0)
    while tb < t[-1] if t.size else False:
        amp = rng.uniform(0.85, 1.0)
        blink += amp * np.clip(np.sin(np.pi * np.clip((t - tb) / 0.15, 0, 1)), 0, 1)
        tb += rng.uniform(3.0, 5.0)
    _add(w, index, "eyeBlinkLeft", blink)
    _add(w, index, "eyeBlinkRight", blink)
    gaze = np.sin(2 * np.pi * rng.uniform(0.05, 0.15) * t + rng.uniform(0, 2 * np.pi))
    _add(w, index, "eyeLookOutLeft", 0.15 * np.clip(gaze, 0, None))
    _add(w, index, "eyeLookInRight", 0.15 * np.clip(gaze, 0, None))
    _add(w, index, "eyeLookInLeft", 0.15 * np.clip(-gaze, 0, None))
    _add(w, index, "eyeLookOutRight", 0.15 * np.clip(-gaze, 0, None))
