"""BeatAlign (BEAT / CaMN): how well motion pauses line up with audio onsets.

    BeatAlign = (1/|B_a|) sum_{b in B_a} exp(-min_{m in B_m} (b - m)^2 / (2 sigma^2)),  sigma = 0.3 s,

with audio beats ``B_a`` (onsets) and motion beats ``B_m`` (local minima of speed). Higher is
better, in [0, 1]. The paper calls it a Chamfer distance between beat sets; the code
(``utils/metric.py``, docs/reference_code.md#beatalign-reference) averages over audio beats as written above.

Variants (``variant=``, a name of :data:`VARIANTS` or a :class:`BeatAlignVariant`)
--------------------------------------------------------------------------------------
- ``"beatlite"`` (default): joint *positions*, per-joint speed by central differences, minima with
  ``order=2`` per joint, one score per joint and the mean over the joints that have beats;
  correct audio times.
- ``"reference"`` reproduces BEAT's code: Euler-angle speed of columns 36:39 of the
  141-d ``spine_neck_141`` vector (the third triplet of its ``30:39`` slice, which the code
  believed to be the right wrist but which is the right ring finger), forward differences,
  only the 10-500 s window, audio onsets backtracked to RMS minima and converted to seconds
  with librosa's default 22050 Hz (times x 0.726 at 16 kHz). Each piece is a field of
  :class:`BeatAlignVariant`: ``dataclasses.replace(VARIANTS["reference"], window=None)`` mixes them.
- EMAGE / BEAT2's "BC" (:func:`emage_beat_align`): the same score re-implemented by BEAT's authors for EMAGE on
  joint positions, speeds normalised by the training mean, a 0.3 threshold, minima of order 7 at 30 fps, 2 s
  left out at both ends.

Taught in notebooks/04_metrics.ipynb, section 3 (BeatAlign and beat consistency); the idea first in notebooks/03_audio_and_text_features.ipynb, section 4.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from beatlite.constants import FPS
from beatlite.metrics._checks import as_array, as_list, positive
from beatlite.metrics.beats import (
    alignment_score,
    audio_beats,
    euler_speed,
    gaussian_alignment,
    local_minima,
    position_speed,
)

#: Columns of the 141-d vector whose Euler speed the reference scores ("beat_right_wrist" = 30:39[6:9]).
REFERENCE_COLUMNS_141 = (36, 37, 38)
#: Evaluation window of the reference, seconds.
REFERENCE_WINDOW = (10.0, 500.0)


@dataclasses.dataclass(frozen=True)
class BeatAlignVariant:
    """Every choice that distinguishes one BeatAlign definition from another.

    Attributes
    ----------
    motion_kind : "positions" or "euler"
        Speed of joint positions (central differences; motion (T, J, 3) cm) or of Euler triplets
        (forward differences; motion (T, C) degrees).
    euler_columns : tuple of int
        Channel triplets scored in the Euler case (default: the reference's 36:39 of 141).
    order : int
        Neighbours on each side a speed minimum must beat (``argrelextrema`` order; 2 in BEAT).
    backtrack, legacy_sr, peak_pick, hop_length
        Audio onset options of :func:`beatlite.metrics.beats.audio_beats`.
    window : (start, end) seconds or None
        Score only this part of each take (beat times relative to ``start``); the reference
        uses (10, 500).

    Examples
    --------
    >>> VARIANTS["beatlite"].motion_kind, VARIANTS["beatlite"].order
    ('positions', 2)
    >>> BeatAlignVariant(motion_kind="euler", window=(10, 500)).window
    (10, 500)
    """

    motion_kind: str = "positions"
    euler_columns: tuple[int, ...] = REFERENCE_COLUMNS_141
    order: int = 2
    backtrack: str | None = None
    legacy_sr: bool = False
    peak_pick: str = "beatlite"
    hop_length: int = 512
    window: tuple[float, float] | None = None

    def audio_beats(self, audio: np.ndarray, sr: int) -> np.ndarray:
        """Onset times (s) of one take's audio as this variant detects them (window applied)."""
        y = as_array(audio, "audio", ndim=1, dtype=np.float32)
        if self.window is not None:
            a, b = _window_indices(self.window, sr, y.shape[0])
            y = y[a:b]
        return audio_beats(
            y, sr, hop_length=self.hop_length, backtrack=self.backtrack, legacy_sr=self.legacy_sr,
            peak_pick=self.peak_pick,
        )  # fmt: skip

    def motion_beats(self, motion: np.ndarray, fps: float) -> list[np.ndarray]:
        """Speed-minimum motion beats (s), one array per joint (positions) or triplet (Euler)."""
        if self.motion_kind == "positions":
            speed = position_speed(as_array(motion, "motion", ndim=3, last=3), fps)
        elif self.motion_kind == "euler":
            speed = euler_speed(as_array(motion, "motion", ndim=2), self.euler_columns, fps)
        else:
            raise ValueError(f"motion_kind must be 'positions' or 'euler', got {self.motion_kind!r}")
        if self.window is not None:
            a, b = _window_indices(self.window, fps, speed.shape[0])
            speed = speed[a:b]
        return [local_minima(speed[:, k], self.order) / fps for k in range(speed.shape[1])]


VARIANTS: dict[str, BeatAlignVariant] = {
    "beatlite": BeatAlignVariant(),
    "reference": BeatAlignVariant(
        motion_kind="euler", backtrack="rms", legacy_sr=True, peak_pick="librosa", window=REFERENCE_WINDOW
    ),
}
"""The named BeatAlign definitions: beatlite's (positions) and BEAT's reference code."""


def beat_align(
    audio: np.ndarray | list[np.ndarray],
    sr: int,
    motion: np.ndarray | list[np.ndarray],
    fps: float = FPS,
    *,
    sigma: float = 0.3,
    variant: str | BeatAlignVariant = "beatlite",
    direction: str = "audio_to_motion",
    audio_beats: np.ndarray | list[np.ndarray] | None = None,
) -> float:
    """BeatAlign of one take or the mean over several takes.

    Parameters
    ----------
    audio : (N,) float or list of (N_i,)
        Mono waveform(s) at ``sr``, aligned with the motion (sample 0 = frame 0). Unused when
        ``audio_beats`` is given (pass ``None``).
    sr : int
        Audio sample rate in Hz.
    motion : (T, J, 3) positions in cm (``"beatlite"``) or (T, C) Euler degrees (``"reference"``),
        or a list of such, one per take. To score some joints only, pass ``positions[:, joints]``.
    fps : float
        Motion frame rate.
    sigma : float
        Gaussian width in seconds (0.3 for BEAT).
    variant : str or BeatAlignVariant
        A name of :data:`VARIANTS` (``"beatlite"``, ``"reference"``) or a custom variant.
    direction : "audio_to_motion" | "motion_to_audio" | "symmetric"
        Which beats are averaged over (both references: audio -> motion; BEAT's supplement
        writes the average over gesture beats, ``"motion_to_audio"``).
    audio_beats : (A,) float or list, optional
        Precomputed onset times in seconds, one array per take, as ``variant.audio_beats(y, sr)``
        returns them (compute them once when scoring several models on the same audio).

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
    >>> from beatlite.metrics.alignment import beat_align
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
    v = _variant(variant)
    fps = positive(fps, "fps")
    motions, many = as_list(motion, "motion")
    beats = _audio_beats_per_take(audio, sr, audio_beats, v, len(motions), many)
    scores = [_take_score(a, v.motion_beats(m, fps), sigma, direction) for a, m in zip(beats, motions)]
    scores = [s for s in scores if np.isfinite(s)]
    return float(np.mean(scores)) if scores else float("nan")


def motion_beat_times(
    motion: np.ndarray, fps: float = FPS, *, variant: str | BeatAlignVariant = "beatlite"
) -> list[np.ndarray]:
    """Speed-minimum motion beats of one take, one array of times (s) per scored joint or triplet.

    Parameters
    ----------
    motion : (T, J, 3) positions cm, or (T, C) Euler degrees (an ``"euler"`` variant)
    fps : float
    variant : str or BeatAlignVariant
        As :func:`beat_align`; with a ``window`` the speed curve is cut to frames
        ``[start * fps, end * fps)`` before the minima search and times are relative to ``start``.

    Returns
    -------
    list of (K_j,) float64
        Beat times ``index / fps`` per joint (positions) or triplet (Euler).

    Examples
    --------
    >>> frames = np.arange(60)
    >>> motion = np.zeros((60, 1, 3))
    >>> motion[:, 0, 0] = 10 * np.cos(np.pi * frames / 12)  # (T, J, 3) cm, turns every 12 frames
    >>> [t.round(6).tolist() for t in motion_beat_times(motion, 15)]  # the turns: frames 12, 24, 36, 48
    [[0.8, 1.6, 2.4, 3.2]]
    """
    return _variant(variant).motion_beats(motion, positive(fps, "fps"))


def _variant(variant: str | BeatAlignVariant) -> BeatAlignVariant:
    v = VARIANTS.get(variant) if isinstance(variant, str) else variant
    if not isinstance(v, BeatAlignVariant):
        raise ValueError(f"variant must be one of {sorted(VARIANTS)} or a BeatAlignVariant, got {variant!r}")
    return v


def _audio_beats_per_take(
    audio, sr, given, variant: BeatAlignVariant, n: int, many: bool
) -> list[np.ndarray]:
    """One array of audio onset times per take: the given ones, or detected from ``audio``."""
    if given is not None:
        items, many_b = as_list(given, "audio_beats") if many else ([given], False)
        beats = [as_array(b, f"audio_beats[{i}]", ndim=1) for i, b in enumerate(items)]
    else:
        items, many_b = as_list(audio, "audio")
        beats = [variant.audio_beats(y, sr) for y in items]
    if many_b != many or len(beats) != n:
        raise ValueError(
            f"audio (or audio_beats) and motion must both be one take or lists of equal length, got "
            f"{len(beats)} and {n} takes"
        )
    return beats


def _take_score(a_times: np.ndarray, m_times: list[np.ndarray], sigma: float, direction: str) -> float:
    """BeatAlign of one take; NaN when it has no audio beat (audio -> motion)."""
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


# ----------------------------------------------------------------------------- EMAGE / BEAT2's "BC"
#: EMAGE's parameters (PantoMatrix, ``scripts/EMAGE_2024/utils/metric.py``, class ``alignment``, and its trainers),
#: stated there at 30 fps and kept here in seconds: minima over 7 frames on each side, a normalised speed above
#: 0.3 at a beat, ``align_mask`` = 60 frames (2 s) left out at both ends of each take.
EMAGE_ORDER_S = 7 / 30
EMAGE_MIN_SPEED = 0.3
EMAGE_SKIP_S = 2.0


def _emage_frames(fps: float, order_s: float, skip_s: float) -> tuple[int, int]:
    return max(1, int(round(order_s * fps))), int(round(skip_s * fps))


def emage_audio_beats(
    audio: np.ndarray, sr: int, n_frames: int, fps: float = FPS, *, skip_s: float = EMAGE_SKIP_S
) -> np.ndarray:
    """EMAGE's audio beats of one take: librosa's onsets (hop 512, in seconds at ``sr``) of the take's audio
    without its first and last ``skip_s`` seconds, times relative to ``skip_s``.

    Parameters
    ----------
    audio : (N,) float
    sr : int
    n_frames : int
        The take's motion frames (the audio is first cut to them, as EMAGE does).
    fps : float
    skip_s : float

    Returns
    -------
    (A,) float64 seconds.

    Examples
    --------
    >>> sr = 16000
    >>> audio = np.zeros(6 * sr, dtype=np.float32)
    >>> audio[[5 * sr // 2, 7 * sr // 2]] = 1.0  # clicks at 2.5 s and 3.5 s
    >>> beats = emage_audio_beats(audio, sr, n_frames=90, fps=15)  # 6 s of motion, 2 s skipped at each end
    >>> beats.round(3).tolist()  # relative to 2 s, in hops of 32 ms; librosa's peak picking marks a click twice
    [0.512, 0.544, 1.504, 1.536]
    """
    y = as_array(audio, "audio", ndim=1, dtype=np.float32)[: int(sr / positive(fps, "fps") * n_frames)]
    offset = int(_emage_frames(fps, EMAGE_ORDER_S, skip_s)[1] * sr / fps)
    return audio_beats(y[offset : len(y) - offset], sr, hop_length=512, peak_pick="librosa")


def emage_beat_align(
    audio_beats: list[np.ndarray],
    positions: list[np.ndarray],
    fps: float,
    mean_speed: np.ndarray,
    *,
    sigma: float = 0.3,
    order_s: float = EMAGE_ORDER_S,
    min_speed: float = EMAGE_MIN_SPEED,
    skip_s: float = EMAGE_SKIP_S,
) -> float:
    """EMAGE / BEAT2's "BC": BEAT's BeatAlign re-implemented on joint positions (Liu et al., EMAGE, CVPR 2024).

    Per take (frames ``skip = skip_s * fps`` to ``T - skip``), per joint: speed by central differences
    (:func:`~beatlite.metrics.beats.position_speed`) divided by the joint's mean training speed, motion beats
    at its strict local minima over ``order_s * fps`` frames on each side where the normalised speed exceeds
    ``min_speed`` (read, as EMAGE's code does, at the minimum's index *within the cut*, i.e. frame ``i`` of the
    take for the minimum at frame ``skip + i``), and the Gaussian alignment over the audio beats
    (:func:`~beatlite.metrics.beats.gaussian_alignment`, σ = 0.3 s; a joint without beats scores 0). The take
    scores the mean over its joints; takes are weighted by their scored frames ``T - 2 skip``.
    It differs from ``beat_align``: normalised speeds, a threshold, order 7 at 30 fps, joints without beats
    counted as 0, 2 s skipped at both ends, frame-weighted takes.

    Parameters
    ----------
    audio_beats : list of (A_k,) float
        :func:`emage_audio_beats` of each take.
    positions : list of (T_k, J, 3) float, cm
        The scored joints of each take.
    fps : float
    mean_speed : (J,) float, cm/s
        Mean speed of each joint over the training data (EMAGE's ``avg_vel``).
    sigma, order_s, min_speed, skip_s : float

    Returns
    -------
    float in [0, 1]; NaN when no take is longer than ``2 skip_s`` with audio beats.

    Examples
    --------
    >>> fps, frames = 15, np.arange(90)
    >>> positions = np.zeros((90, 1, 3))
    >>> positions[:, 0, 0] = 10 * np.cos(np.pi * frames / 12)  # (T, J, 3) cm, turns every 12 frames
    >>> mean_speed = np.array([np.abs(np.gradient(positions[:, 0, 0])).mean() * fps])
    >>> # scored frames 30..59 (2 s skipped): motion beats at frames 36 and 48, i.e. 0.4 and 1.2 s after the skip
    >>> emage_beat_align([np.array([0.4, 1.2])], [positions], fps, mean_speed)
    1.0
    >>> round(emage_beat_align([np.array([0.8, 1.6])], [positions], fps, mean_speed), 4)  # 0.4 s off: exp(-0.16 / 0.18)
    0.4111
    """
    fps = positive(fps, "fps")
    order, skip = _emage_frames(fps, order_s, skip_s)
    scale = as_array(mean_speed, "mean_speed", ndim=1)
    total, weight = 0.0, 0
    for a, p in zip(audio_beats, positions, strict=True):
        n = len(p) - 2 * skip
        if n < 3 or len(a) == 0:
            continue
        speed = position_speed(p, fps) / scale
        scores = []
        for j in range(speed.shape[1]):
            found = local_minima(speed[skip : skip + n, j], order)
            kept = found[speed[found, j] > min_speed]
            scores.append(gaussian_alignment(a, kept / fps, sigma))
        total += float(np.mean(scores)) * n
        weight += n
    return total / weight if weight else float("nan")
