"""BeatAlign (BEAT / CaMN): how well motion pauses line up with audio onsets.

    BeatAlign = (1/|B_a|) sum_{b in B_a} exp(-min_{m in B_m} (b - m)^2 / (2 sigma^2)),  sigma = 0.3 s,

with audio beats ``B_a`` (onsets) and motion beats ``B_m`` (local minima of speed). Higher is
better, in [0, 1]. The paper calls it a Chamfer distance between beat sets; the code
(``utils/metric.py``, docs/reference_code.md#beatalign-reference) averages over audio beats as written above.

Variants
--------
- default (beatlite): joint *positions*, per-joint speed by central differences, minima with
  ``order=2`` per joint, one score per joint and the mean over the joints that have beats;
  correct audio times.
- ``legacy=True`` reproduces the reference code: Euler-angle speed of columns 36:39 of the
  141-d ``spine_neck_141`` vector (the third triplet of its ``30:39`` slice, which the code
  believed to be the right wrist but which is the right ring finger), forward differences,
  only the 10-500 s window, audio onsets backtracked to RMS minima and converted to seconds
  with librosa's default 22050 Hz (times x 0.726 at 16 kHz). Each piece is also selectable.

Taught in notebooks/04_metrics.ipynb, section 3 (BeatAlign and beat consistency); the idea first in notebooks/03_audio_and_text_features.ipynb, section 4.
"""

from __future__ import annotations

import numpy as np

from beatlite.metrics._checks import as_array, as_list, positive
from beatlite.metrics.beats import (
    alignment_score,
    audio_beats,
    euler_speed,
    local_minima,
    position_speed,
)

#: Columns of the 141-d vector whose Euler speed the reference scores ("beat_right_wrist" = 30:39[6:9]).
REFERENCE_COLUMNS_141 = (36, 37, 38)
#: Evaluation window of the reference, seconds.
REFERENCE_WINDOW = (10.0, 500.0)


def beat_align(
    audio: np.ndarray | list[np.ndarray],
    sr: int,
    motion: np.ndarray | list[np.ndarray],
    fps: float = 15.0,
    *,
    sigma: float = 0.3,
    motion_kind: str = "positions",
    joints: list[int] | np.ndarray | None = None,
    euler_columns: tuple[int, ...] | list[int] = REFERENCE_COLUMNS_141,
    order: int = 2,
    backtrack: str | None = None,
    legacy_sr: bool = False,
    peak_pick: str = "beatlite",
    window: tuple[float, float] | None = None,
    direction: str = "audio_to_motion",
    hop_length: int = 512,
    legacy: bool = False,
) -> float:
    """BeatAlign of one take or the mean over several takes.

    Parameters
    ----------
    audio : (N,) float or list of (N_i,)
        Mono waveform(s) at ``sr``, aligned with the motion (sample 0 = frame 0).
    sr : int
        Audio sample rate in Hz.
    motion : (T, J, 3) positions in cm (``motion_kind="positions"``) or (T, C) Euler degrees
        (``motion_kind="euler"``), or a list of such, one per take.
    fps : float
        Motion frame rate.
    sigma : float
        Gaussian width in seconds (0.3 for BEAT).
    motion_kind : "positions" or "euler"
        Speed of joint positions (central differences) or of Euler triplets (forward differences).
    joints : (K,) int, optional
        Joints scored in the positions variant (default: all J).
    euler_columns : (3K,) int
        Channel triplets scored in the Euler variant (default: the reference's 36:39 of 141).
    order : int
        Neighbours on each side a speed minimum must beat (``argrelextrema`` order; 2 in BEAT).
    backtrack, legacy_sr, peak_pick, hop_length
        Audio onset options, see :func:`beatlite.metrics.beats.audio_beats`.
    window : (start, end) seconds, optional
        Score only this part of each take (beat times become relative to ``start``);
        the reference uses (10, 500).
    direction : "audio_to_motion" | "motion_to_audio" | "symmetric"
        Which beats are averaged over (both references: audio -> motion).
    legacy : bool
        Shortcut for the reference settings: ``motion_kind="euler"`` with the default
        ``euler_columns``, ``order=2``, ``backtrack="rms"``, ``legacy_sr=True``, ``peak_pick="librosa"``,
        ``window=(10, 500)``.

    Returns
    -------
    float in [0, 1]
        The mean over takes (unweighted, as the reference averages test files). Takes
        without audio beats are skipped; NaN if no take has any. Within a take, a scored
        joint/triplet without any motion beat is left out of the joint mean; a take whose
        joints have no motion beat at all (a frozen pose) scores 0.

    Examples
    --------
    Four seconds of audio with a click every 0.8 s (0.8 s = 12 frames at 15 fps = 25 STFT
    hops of 512 samples at 16 kHz), and one joint swinging back and forth, turning round
    (speed 0) at frames 12, 24, 36 and 48. librosa reports each click one hop (0.032 s)
    late, so every audio beat is 0.032 s from a motion beat:
    ``BeatAlign = exp(-0.032^2 / (2 * 0.3^2)) = 0.9943``.

    >>> import numpy as np
    >>> from beatlite.metrics.beat_align import beat_align
    >>> sr, fps = 16000, 15
    >>> audio = np.zeros(4 * sr, dtype=np.float32)
    >>> audio[[12800, 25600, 38400, 51200]] = 1.0
    >>> frames = np.arange(60)
    >>> motion = np.zeros((60, 1, 3))
    >>> motion[:, 0, 0] = 10 * np.cos(np.pi * frames / 12)  # (T, J, 3) cm, turns every 12 frames
    >>> round(beat_align(audio, sr, motion, fps, sigma=0.3), 4)
    0.9943
    >>> round(float(np.exp(-(0.032**2) / (2 * 0.3**2))), 4)
    0.9943

    With the swing shifted by 6 frames (turns at 0.4, 1.2, 2.0 and 2.8 s), the nearest
    motion beat is 0.4 - 0.032 = 0.368 s away: ``exp(-0.368^2 / 0.18) = 0.4713``.

    >>> motion[:, 0, 0] = 10 * np.sin(np.pi * frames / 12)
    >>> round(beat_align(audio, sr, motion, fps, sigma=0.3), 4)
    0.4713
    """
    if legacy:
        motion_kind, backtrack, legacy_sr, order, peak_pick = "euler", "rms", True, 2, "librosa"
        window = REFERENCE_WINDOW if window is None else window
    if motion_kind not in ("positions", "euler"):
        raise ValueError(f"motion_kind must be 'positions' or 'euler', got {motion_kind!r}")
    fps = positive(fps, "fps")
    audios, many_a = as_list(audio, "audio")
    motions, many_m = as_list(motion, "motion")
    if many_a != many_m or len(audios) != len(motions):
        raise ValueError(
            f"audio and motion must both be one take or lists of equal length, got "
            f"{len(audios)} audio and {len(motions)} motion takes"
        )
    scores = []
    for i, (y, m) in enumerate(zip(audios, motions)):
        s = beat_align_take(
            y, sr, m, fps, sigma=sigma, motion_kind=motion_kind, joints=joints,
            euler_columns=euler_columns, order=order, backtrack=backtrack, legacy_sr=legacy_sr,
            peak_pick=peak_pick, window=window, direction=direction, hop_length=hop_length, _name=f"take {i}",
        )  # fmt: skip
        if np.isfinite(s):
            scores.append(s)
    return float(np.mean(scores)) if scores else float("nan")


def motion_beat_times(
    motion: np.ndarray,
    fps: float,
    *,
    motion_kind: str = "positions",
    joints: list[int] | np.ndarray | None = None,
    euler_columns: tuple[int, ...] | list[int] = REFERENCE_COLUMNS_141,
    order: int = 2,
    window: tuple[float, float] | None = None,
) -> list[np.ndarray]:
    """Speed-minimum motion beats, one array of times (seconds) per scored joint or triplet.

    Parameters are those of :func:`beat_align`. With a ``window``, the speed curve is cut
    to frames ``[start * fps, end * fps)`` before the minima search and times are relative
    to ``start`` (as the reference does).

    Returns
    -------
    list of (K_j,) float64
        Beat times ``index / fps`` per joint (positions) or triplet (Euler).
    """
    if motion_kind == "positions":
        p = as_array(motion, "motion", ndim=3, last=3)
        if joints is not None:
            jj = np.asarray(joints, dtype=np.int64).ravel()
            if jj.size == 0 or jj.min() < -p.shape[1] or jj.max() >= p.shape[1]:
                raise ValueError(f"joints {jj.tolist()} out of range for motion of shape {p.shape}")
            p = p[:, jj]
        speed = position_speed(p, fps)
    elif motion_kind == "euler":
        speed = euler_speed(as_array(motion, "motion", ndim=2), euler_columns, fps)
    else:
        raise ValueError(f"motion_kind must be 'positions' or 'euler', got {motion_kind!r}")
    if window is not None:
        a, b = _window_indices(window, fps, speed.shape[0])
        speed = speed[a:b]
    return [local_minima(speed[:, k], order) / fps for k in range(speed.shape[1])]


def beat_align_take(
    audio: np.ndarray,
    sr: int,
    motion: np.ndarray,
    fps: float = 15.0,
    *,
    sigma: float = 0.3,
    motion_kind: str = "positions",
    joints: list[int] | np.ndarray | None = None,
    euler_columns: tuple[int, ...] | list[int] = REFERENCE_COLUMNS_141,
    order: int = 2,
    backtrack: str | None = None,
    legacy_sr: bool = False,
    peak_pick: str = "beatlite",
    window: tuple[float, float] | None = None,
    direction: str = "audio_to_motion",
    hop_length: int = 512,
    _name: str = "take",
) -> float:
    """BeatAlign of a single take (see :func:`beat_align`); NaN when it has no audio beat."""
    y = as_array(audio, "audio", ndim=1, dtype=np.float32)
    if window is not None:
        a, b = _window_indices(window, sr, y.shape[0])
        y = y[a:b]
    a_times = audio_beats(
        y, sr, hop_length=hop_length, backtrack=backtrack, legacy_sr=legacy_sr, peak_pick=peak_pick
    )
    m_times = motion_beat_times(
        motion, fps, motion_kind=motion_kind, joints=joints, euler_columns=euler_columns,
        order=order, window=window,
    )  # fmt: skip
    if a_times.size == 0 and direction == "audio_to_motion":
        return float("nan")
    per_joint = [alignment_score(a_times, m, sigma, direction) for m in m_times if m.size > 0]
    per_joint = [s for s in per_joint if np.isfinite(s)]
    if not per_joint:
        return 0.0 if a_times.size else float("nan")
    return float(np.mean(per_joint))


def _window_indices(window: tuple[float, float], rate: float, n: int) -> tuple[int, int]:
    start, end = float(window[0]), float(window[1])
    if not 0 <= start < end:
        raise ValueError(f"window must be (start, end) seconds with 0 <= start < end, got {window}")
    return min(int(start * rate), n), min(int(end * rate), n)
