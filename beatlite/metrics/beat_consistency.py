"""Beat Consistency (BC, HA2G / TED-Expressive): audio onsets vs pauses in bone-angle change.

HA2G tracks motion beats with the angles *between* bones, which do not depend on how fast
a joint moves in space:

    theta_{t,p} = angle between the two vectors of pair p, / pi
    c_t = (1/P) sum_p |theta_{t,p} - theta_{t-1,p}| / MAAC_p            (c_0 = 0)
    motion beat at t in [2, T-2]: c_t strict local minimum and a drop >= 0.03 to a neighbour
    BC = (1/|A|) sum_{a in A} exp(-min_m (a - m)^2 / (2 sigma^2)),     sigma = 0.1 s

with MAAC_p the mean absolute frame-to-frame change of pair p on the training data (HA2G
eq. 10) and A the audio onsets. Pairs whose MAAC is (near) zero never move and are left out
of the mean (:func:`beatlite.metrics.beats.drop_rigid_pairs`: ``MAAC_p <= 1e-5 max_q MAAC_q``);
dividing by their round-off MAAC would let round-off decide the beats. Vectors are the 42 TED bone directions (not mean-subtracted)
plus the two palm normals; the pairs are ``beatlite.skeleton.ted.ANGLE_PAIRS``.

HA2G scores each 34-frame validation clip with its own audio and averages the clips weighted
by their number of audio beats, skipping clips without motion beats (``clip_length=34``).
beatlite's default scores the whole take at once.
"""

from __future__ import annotations

import numpy as np

from beatlite.metrics._checks import as_array, as_list, positive
from beatlite.metrics.beats import (
    alignment_score,
    angle_change_beats,
    angle_change_curve,
    append_palm_normals,
    audio_beats,
    drop_rigid_pairs,
    mean_angle_change,
)


def default_angle_pairs() -> np.ndarray:
    """HA2G's 41 angle pairs over the 44 vectors (42 bones + 2 palm normals), (41, 2) int64.

    Taken from ``beatlite.skeleton.ted.ANGLE_PAIRS``.
    """
    try:
        from beatlite.skeleton.ted import ANGLE_PAIRS
    except ImportError as exc:  # pragma: no cover - depends on a module written in parallel
        raise ImportError(
            "beatlite.skeleton.ted.ANGLE_PAIRS is not available; pass pairs=(P, 2) explicitly"
        ) from exc
    return np.asarray(ANGLE_PAIRS, dtype=np.int64).reshape(-1, 2)


def prepare_directions(
    directions: np.ndarray, *, mean_direction: np.ndarray | None = None, palm_normals: bool = True
) -> np.ndarray:
    """Undo mean subtraction, renormalise and append palm normals.

    Parameters
    ----------
    directions : (T, 42, 3) or (T, 126) float
        TED bone directions; mean-subtracted ("dirvec") if ``mean_direction`` is given.
    mean_direction : (42, 3) or (126,) float, optional
        The mean added back first (the HA2G README's bug fix).
    palm_normals : bool
        Append the two palm normals (42 -> 44 vectors).

    Returns
    -------
    (T, 42 or 44, 3) float64 unit vectors.
    """
    d = as_array(directions, "directions", ndim=(2, 3))
    if d.ndim == 2:
        if d.shape[1] % 3:
            raise ValueError(f"directions (T, 3V) must have a multiple of 3 columns, got shape {d.shape}")
        d = d.reshape(d.shape[0], -1, 3)
    if d.shape[-1] != 3:
        raise ValueError(f"directions must be (T, V, 3), got shape {d.shape}")
    if mean_direction is not None:
        mean = as_array(mean_direction, "mean_direction", ndim=(1, 2)).reshape(-1, 3)
        if mean.shape != d.shape[1:]:
            raise ValueError(f"mean_direction {mean.shape} does not match directions {d.shape}")
        d = d + mean
    n = np.linalg.norm(d, axis=-1, keepdims=True)
    d = np.divide(d, n, out=np.zeros_like(d), where=n > 1e-12)
    return append_palm_normals(d) if palm_normals else d


def beat_consistency(
    audio: np.ndarray | list[np.ndarray],
    sr: int,
    directions: np.ndarray | list[np.ndarray],
    fps: float = 15.0,
    *,
    sigma: float = 0.1,
    pairs: np.ndarray | None = None,
    change_angle: np.ndarray | None = None,
    threshold: float = 0.03,
    mean_direction: np.ndarray | None = None,
    palm_normals: bool = True,
    clip_length: int | None = None,
    clip_stride: int = 10,
    direction: str = "audio_to_motion",
    backtrack: str | None = None,
    peak_pick: str = "beatlite",
    hop_length: int = 512,
    legacy: bool = False,
) -> float:
    """Beat Consistency score of one take or several.

    Parameters
    ----------
    audio : (N,) float or list
        Mono waveform(s) at ``sr``, aligned with the motion.
    sr : int
        Sample rate, Hz.
    directions : (T, 42, 3) / (T, 126) float or list
        TED bone directions per frame (see :func:`prepare_directions`). With
        ``palm_normals=False`` any (T, V, 3) vectors matching ``pairs`` are accepted.
    fps : float
        Motion frame rate.
    sigma : float
        Gaussian width in seconds (0.1 in HA2G).
    pairs : (P, 2) int, optional
        Angle pairs (default: ``beatlite.skeleton.ted.ANGLE_PAIRS``).
    change_angle : (P,) float, optional
        MAAC per pair from the **training** data (:func:`beatlite.metrics.beats.mean_angle_change`).
        Default: computed from the given directions themselves (a fallback; pass the
        ground-truth / training values when comparing models). Pairs with a (near) zero MAAC
        are dropped (:func:`beatlite.metrics.beats.drop_rigid_pairs`).
    threshold : float
        Minimum drop of a motion beat (0.03).
    mean_direction, palm_normals
        See :func:`prepare_directions`.
    clip_length, clip_stride : int, optional
        HA2G protocol: cut each take into clips of ``clip_length`` frames every
        ``clip_stride`` frames, score each clip with its own audio
        (``round(clip_length / fps * sr)`` samples), and average the clips weighted by their
        number of audio beats, skipping clips without motion beats. ``None``: whole takes,
        averaged weighted by their number of audio beats too.
    direction, backtrack, peak_pick, hop_length
        See :func:`beatlite.metrics.beats.alignment_score` / ``audio_beats``.
    legacy : bool
        The HA2G protocol: ``clip_length=34`` (if not given), ``peak_pick="librosa"``
        (HA2G's ``onset_detect(y=clip, sr=16000, units="time")``), sigma and threshold as given.
        With HA2G's own ``change_angle`` no pair is rigid, so the score is HA2G's formula exactly.

    Returns
    -------
    float in [0, 1]; NaN when no clip/take has both audio and motion beats.
    """
    if legacy:
        clip_length, peak_pick = (34 if clip_length is None else clip_length), "librosa"
    fps = positive(fps, "fps")
    audios, many_a = as_list(audio, "audio")
    dirs, many_d = as_list(directions, "directions")
    if many_a != many_d or len(audios) != len(dirs):
        raise ValueError(
            f"audio and directions must both be one take or lists of equal length, got "
            f"{len(audios)} and {len(dirs)}"
        )
    vecs = [prepare_directions(d, mean_direction=mean_direction, palm_normals=palm_normals) for d in dirs]
    pr = default_angle_pairs() if pairs is None else np.asarray(pairs, dtype=np.int64)
    ca = (
        mean_angle_change(vecs, pr)
        if change_angle is None
        else as_array(change_angle, "change_angle", ndim=1)
    )
    pr, ca = drop_rigid_pairs(pr, ca)  # rigid pairs carry no motion beat
    total, weight = 0.0, 0
    for y, v in zip(audios, vecs):
        y = as_array(y, "audio", ndim=1, dtype=np.float32)
        pieces = [(y, v)] if clip_length is None else _clips(y, sr, v, fps, clip_length, clip_stride)
        for y_c, v_c in pieces:
            a_times = audio_beats(y_c, sr, hop_length=hop_length, backtrack=backtrack, peak_pick=peak_pick)
            m_times = angle_change_beats(angle_change_curve(v_c, pr, ca), fps, threshold=threshold)
            if a_times.size == 0 or m_times.size == 0:
                continue
            total += alignment_score(a_times, m_times, sigma, direction) * a_times.size
            weight += a_times.size
    return total / weight if weight else float("nan")


def _clips(y: np.ndarray, sr: int, v: np.ndarray, fps: float, length: int, stride: int):
    if length < 3 or stride < 1:
        raise ValueError(f"clip_length must be >= 3 and clip_stride >= 1, got {length}, {stride}")
    n_samples = int(round(length / fps * sr))
    for start in range(0, v.shape[0] - length + 1, stride):
        a = int(round(start / fps * sr))
        yield y[a : a + n_samples], v[start : start + length]
