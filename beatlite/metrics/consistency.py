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

Variants (``variant=``, a name of :data:`VARIANTS` or a :class:`BCVariant`): HA2G's code
(``"ha2g"``) scores each 34-frame validation clip with its own audio and averages the clips
weighted by their number of audio beats, skipping clips without motion beats, with librosa's
own peak picking; beatlite's default (``"beatlite"``) scores the whole take at once.

Taught in notebooks/04_metrics.ipynb, section 3 (BeatAlign and beat consistency).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from beatlite.constants import FPS, WINDOW_LENGTH, WINDOW_STRIDE
from beatlite.metrics._checks import as_array, as_list, positive
from beatlite.metrics.beats import (
    RIGID_RTOL,
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

    Examples
    --------
    >>> pairs = default_angle_pairs()
    >>> pairs.shape, int(pairs.max()) < 44
    ((41, 2), True)
    """
    from beatlite.skeleton.ted import ANGLE_PAIRS

    return np.asarray(ANGLE_PAIRS, dtype=np.int64).reshape(-1, 2)


@dataclasses.dataclass(frozen=True)
class BCVariant:
    """Every choice that distinguishes one beat-consistency definition from another.

    Attributes
    ----------
    threshold : float
        Minimum drop of a motion beat (0.03).
    pairs : tuple of (int, int) or None
        Angle pairs over the vectors (None: ``beatlite.skeleton.ted.ANGLE_PAIRS``).
    palm_normals : bool
        Append the two palm normals (42 -> 44 vectors) before measuring angles.
    clip_length, clip_stride : int or None, int
        HA2G's protocol: cut each take into clips of ``clip_length`` frames every ``clip_stride``
        frames, score each clip with its own audio (``round(clip_length / fps * sr)`` samples) and
        average the clips weighted by their number of audio beats, skipping clips without motion
        beats. ``None``: whole takes, weighted the same way.
    direction : str
        See :func:`beatlite.metrics.beats.alignment_score`.
    backtrack, peak_pick, hop_length
        Audio onset options of :func:`beatlite.metrics.beats.audio_beats`.
    rigid_rtol : float
        Angle pairs whose MAAC is at most ``rigid_rtol`` times the largest are rigid and left out
        (:func:`beatlite.metrics.beats.drop_rigid_pairs`); 0 keeps every moving pair.

    Examples
    --------
    >>> VARIANTS["ha2g"].clip_length, VARIANTS["ha2g"].clip_stride
    (34, 10)
    >>> BCVariant(threshold=0.05).palm_normals
    True
    """

    threshold: float = 0.03
    pairs: tuple[tuple[int, int], ...] | None = None
    palm_normals: bool = True
    clip_length: int | None = None
    clip_stride: int = WINDOW_STRIDE
    direction: str = "audio_to_motion"
    backtrack: str | None = None
    peak_pick: str = "beatlite"
    hop_length: int = 512
    rigid_rtol: float = RIGID_RTOL

    def angle_pairs(self) -> np.ndarray:
        """(P, 2) int64 pairs (the default ones when ``pairs`` is None)."""
        return (
            default_angle_pairs() if self.pairs is None else np.asarray(self.pairs, np.int64).reshape(-1, 2)
        )

    def audio_beats(self, audio: np.ndarray, sr: int) -> np.ndarray:
        """Onset times (s) of one take's (or clip's) audio as this variant detects them."""
        return audio_beats(
            audio, sr, hop_length=self.hop_length, backtrack=self.backtrack, peak_pick=self.peak_pick
        )


VARIANTS: dict[str, BCVariant] = {
    "beatlite": BCVariant(),
    "ha2g": BCVariant(clip_length=WINDOW_LENGTH, peak_pick="librosa"),
}
"""The named BC definitions: beatlite's (whole takes) and HA2G's code (34-frame clips)."""


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

    Examples
    --------
    >>> directions = np.tile([0.0, 2.0, 0.0], (5, 42, 1))  # (T, 42, 3), not unit
    >>> out = prepare_directions(directions)
    >>> out.shape, np.allclose(out[:, :42], [0, 1, 0])  # renormalised, two palm normals appended
    ((5, 44, 3), True)
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
    audio: np.ndarray | list[np.ndarray] | None,
    sr: int,
    directions: np.ndarray | list[np.ndarray],
    fps: float = FPS,
    *,
    sigma: float = 0.1,
    change_angle: np.ndarray | None = None,
    variant: str | BCVariant = "beatlite",
    audio_beats: np.ndarray | list[np.ndarray] | None = None,
) -> float:
    """Beat Consistency score of one take or several.

    Parameters
    ----------
    audio : (N,) float or list
        Mono waveform(s) at ``sr``, aligned with the motion (may be None with ``audio_beats``).
    sr : int
        Sample rate, Hz.
    directions : (T, 42, 3) / (T, 126) float or list
        TED bone unit directions per frame (add a "dirvec" window's mean back first, see
        :func:`prepare_directions`). With ``palm_normals=False`` in the variant any (T, V, 3)
        vectors matching its pairs are accepted.
    fps : float
        Motion frame rate.
    sigma : float
        Gaussian width in seconds (0.1 in HA2G).
    change_angle : (P,) float, optional
        MAAC per pair from the **training** data (:func:`beatlite.metrics.beats.mean_angle_change`).
        Default: computed from the given directions themselves (a fallback; pass the
        ground-truth / training values when comparing models). Pairs with a (near) zero MAAC
        are left out (:func:`beatlite.metrics.beats.drop_rigid_pairs`, the variant's ``rigid_rtol``);
        with HA2G's own ``change_angle`` no pair is rigid, so the score is HA2G's formula exactly.
    variant : str or BCVariant
        A name of :data:`VARIANTS` (``"beatlite"``, ``"ha2g"``) or a custom variant.
    audio_beats : (A,) float or list, optional
        Precomputed onset times (s) per take, as ``variant.audio_beats(y, sr)`` returns them; with a clip
        variant, per take the list of per-clip onsets of :func:`clip_audio_beats`.

    Returns
    -------
    float in [0, 1]; NaN when no clip/take has both audio and motion beats.

    Examples
    --------
    Clicks every 0.8 s as in :func:`beatlite.metrics.alignment.beat_align`'s example
    (librosa reports each one 0.032 s late), and 42 bone directions turning about the
    vertical axis, each at its own rate, by an angle ``phi`` that reverses between frames
    11 and 12, 23 and 24, ... Every included angle stops changing there, so the motion
    beats are frames 12, 24, 36, 48 (0.8, 1.6, 2.4, 3.2 s) and
    ``BC = exp(-0.032^2 / (2 * 0.1^2)) = 0.9501``.

    >>> import numpy as np
    >>> from beatlite.metrics.consistency import beat_consistency
    >>> sr, fps = 16000, 15
    >>> audio = np.zeros(4 * sr, dtype=np.float32)
    >>> audio[[12800, 25600, 38400, 51200]] = 1.0
    >>> phi = np.cos(np.pi * (np.arange(60) - 11.5) / 12)  # phi[11] == phi[12], ...
    >>> rng = np.random.default_rng(0)
    >>> base, rate = rng.normal(size=(42, 3)), rng.uniform(0.5, 1.5, size=42)
    >>> angle = rate * phi[:, None]  # (T, 42) rotation about z, radians
    >>> x, y, z = base.T
    >>> directions = np.stack(
    ...     [np.cos(angle) * x - np.sin(angle) * y, np.sin(angle) * x + np.cos(angle) * y,
    ...      np.broadcast_to(z, angle.shape)], axis=-1)  # (T, 42, 3)
    >>> round(beat_consistency(audio, sr, directions, fps, sigma=0.1), 4)
    0.9501
    >>> round(float(np.exp(-(0.032**2) / (2 * 0.1**2))), 4)
    0.9501
    """
    v = VARIANTS.get(variant) if isinstance(variant, str) else variant
    if not isinstance(v, BCVariant):
        raise ValueError(f"variant must be one of {sorted(VARIANTS)} or a BCVariant, got {variant!r}")
    fps = positive(fps, "fps")
    dirs, many = as_list(directions, "directions")
    vecs = [prepare_directions(d, palm_normals=v.palm_normals) for d in dirs]
    pairs = v.angle_pairs()
    ca = (
        mean_angle_change(vecs, pairs)
        if change_angle is None
        else as_array(change_angle, "change_angle", ndim=1)
    )
    pairs, ca = drop_rigid_pairs(
        pairs, ca, rtol=v.rigid_rtol
    )  # once, not per clip: rigid pairs carry no beat
    total, weight = 0.0, 0
    for a_times, vec in _scored_pieces(audio, sr, audio_beats, vecs, many, fps, v):
        m_times = angle_change_beats(
            angle_change_curve(vec, pairs, ca, rigid_rtol=0.0), fps, threshold=v.threshold
        )
        if a_times.size == 0 or m_times.size == 0:
            continue
        total += alignment_score(a_times, m_times, sigma, v.direction) * a_times.size
        weight += a_times.size
    return total / weight if weight else float("nan")


def _scored_pieces(audio, sr, given, vecs, many, fps, v: BCVariant):
    """(audio beat times, vectors) of every take, or of every clip with the clip protocol."""
    if given is not None:
        items, many_b = as_list(given, "audio_beats") if many else ([given], False)
        _same_takes(len(items), many_b, len(vecs), many)
        if v.clip_length is None:
            yield from zip([as_array(b, f"audio_beats[{i}]", ndim=1) for i, b in enumerate(items)], vecs)
            return
        from beatlite.data.windows import window_starts

        for clips, vec in zip(items, vecs):
            starts = window_starts(int(vec.shape[0]), v.clip_length, v.clip_stride).tolist()
            if not isinstance(clips, list | tuple) or len(clips) != len(starts):
                raise ValueError(
                    f"with a clip variant, audio_beats holds per take a list of {len(starts)} per-clip onset "
                    "arrays (clip_audio_beats), not one array per take"
                )
            for b, start in zip(clips, starts):
                yield as_array(b, "audio_beats", ndim=1), vec[start : start + v.clip_length]
        return
    audios, many_a = as_list(audio, "audio")
    _same_takes(len(audios), many_a, len(vecs), many)
    for y, vec in zip(audios, vecs):
        y = as_array(y, "audio", ndim=1, dtype=np.float32)
        if v.clip_length is None:
            yield v.audio_beats(y, sr), vec
            continue
        for y_c, v_c in _clips(y, sr, vec, fps, v.clip_length, v.clip_stride):
            yield v.audio_beats(y_c, sr), v_c


def clip_audio_beats(
    audio: np.ndarray, sr: int, n_frames: int, fps: float = FPS, *, variant: str | BCVariant = "ha2g"
) -> list[np.ndarray]:
    """Onset times (s) of each clip's own audio under a clip variant, in the order the clips are scored.

    One take's list is what :func:`beat_consistency` takes per take as ``audio_beats=`` with that variant
    (the onsets are detected once, e.g. for bootstrap resamples of the same takes).

    Parameters
    ----------
    audio : (N,) float
        The take's waveform at ``sr``.
    sr : int
    n_frames : int
        The take's motion frames (the clips are its 34-frame windows, stride 10).
    fps : float
    variant : str or BCVariant
        A variant with ``clip_length`` (``"ha2g"``).

    Returns
    -------
    list of (A_c,) float64, one per clip.

    Examples
    --------
    >>> sr = 16000
    >>> audio = np.zeros(4 * sr, dtype=np.float32)
    >>> audio[[sr, 3 * sr]] = 1.0  # clicks at 1 s and 3 s
    >>> clips = clip_audio_beats(audio, sr, n_frames=60)  # 34-frame clips every 10 frames: starts 0, 10, 20
    >>> len(clips), [c.round(1).tolist() for c in clips]  # relative to each clip's start (0, 2/3, 4/3 s)
    (3, [[1.0], [0.4], [1.7]])
    """
    v = VARIANTS.get(variant) if isinstance(variant, str) else variant
    if not isinstance(v, BCVariant) or v.clip_length is None:
        raise ValueError(f"variant must be a clip variant (clip_length set), got {variant!r}")
    y = as_array(audio, "audio", ndim=1, dtype=np.float32)
    frames = np.zeros((int(n_frames), 1))
    return [
        v.audio_beats(y_c, sr)
        for y_c, _ in _clips(y, sr, frames, positive(fps, "fps"), v.clip_length, v.clip_stride)
    ]


def _same_takes(n_audio: int, many_audio: bool, n_dirs: int, many_dirs: bool) -> None:
    if many_audio != many_dirs or n_audio != n_dirs:
        raise ValueError(
            f"audio (or audio_beats) and directions must both be one take or lists of equal length, "
            f"got {n_audio} and {n_dirs}"
        )


def _clips(y: np.ndarray, sr: int, v: np.ndarray, fps: float, length: int, stride: int):
    if length < 3 or stride < 1:
        raise ValueError(f"clip_length must be >= 3 and clip_stride >= 1, got {length}, {stride}")
    from beatlite.data.windows import window_starts

    n_samples = int(round(length / fps * sr))
    for start in window_starts(int(v.shape[0]), length, stride).tolist():
        a = int(round(start / fps * sr))
        yield y[a : a + n_samples], v[start : start + length]
