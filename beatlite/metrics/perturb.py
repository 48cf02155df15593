"""What a metric rewards: systems made from the ground truth by simple, fully understood changes.

No trained model is needed to see what FGD, SRGR, BeatAlign, beat consistency and the diversity
scores reward: score the ground truth's own motion and perturbations of it (white noise, a
smaller range, a delay, another take, a frozen pose), and compare. This module builds those
systems from ``spine_neck_141`` Euler tracks and turns them into the :class:`Takes` that
:func:`beatlite.metrics.evaluate` scores.

=============================  ============================================================
:func:`euler_takes`            (T, 141) Euler tracks -> positions, TED directions, Euler
:func:`perturbed_systems`      ground truth, jitter, half range, delayed, another take, frozen
:func:`delayed`                a track played ``frames`` late (first frame repeated)
:func:`subset_spread`          SRGR and L1div over random subsets of clips (BEAT Fig. 6)
:func:`shifted_beat_align`     BeatAlign of the motion vs the same motion circularly shifted
=============================  ============================================================

Taught in notebooks/04_metrics.ipynb, sections 0 (the systems) and 5 (what each metric rewards,
BEAT Figure 6); :func:`shifted_beat_align` in notebooks/03_audio_and_text_features.ipynb, section 4.
"""

from __future__ import annotations

import numpy as np

from beatlite.constants import FPS, SR, WINDOW_LENGTH, WINDOW_STRIDE
from beatlite.metrics.scoring import Takes

#: The systems of :func:`perturbed_systems`, in table order, with what each one is.
SYSTEMS = {
    "ground truth": "the takes themselves",
    "jitter": "ground truth + white noise of `jitter_deg` degrees on every channel",
    "half range": "every channel pulled halfway to the take's mean pose (right timing, small motion)",
    "delayed 1 s": "the motion `delay_frames` frames late (first frame repeated)",
    "another take": "the motion of the next take, cut or repeated to this take's length (a random clip)",
    "frozen mean pose": "the take's mean pose on every frame",
}


def euler_takes(eulers: list[np.ndarray], fps: float = FPS) -> Takes:
    """The metric inputs of ``spine_neck_141`` Euler tracks: positions, TED directions and the Euler itself.

    Parameters
    ----------
    eulers : list of (T_k, 141) float, degrees
        CaMN's output layout; every other BEAT channel is at rest and the root at the origin.
    fps : float
        Frame rate (only stored in the motion used for forward kinematics).

    Returns
    -------
    Takes
        ``positions`` (T_k, 47, 3) cm of the 47 ``spine_neck_141`` joints, ``directions``
        (T_k, 42, 3) unit TED-43 bone directions, ``euler`` the input as float64; no features.

    Examples
    --------
    >>> takes = euler_takes([np.zeros((5, 141))])  # the rest pose
    >>> takes.positions[0].shape, takes.directions[0].shape
    ((5, 47, 3), (5, 42, 3))
    >>> bool(np.allclose(np.linalg.norm(takes.directions[0], axis=-1), 1.0))
    True
    """
    from beatlite.io.motion import Motion
    from beatlite.skeleton.beat import JOINT_SUBSETS, beat_skeleton, expand_subset
    from beatlite.skeleton.directions import positions_to_directions
    from beatlite.skeleton.ted import TED_BONES, beat_to_ted43

    skeleton = beat_skeleton()
    joints = skeleton.indices(JOINT_SUBSETS["spine_neck_141"])
    positions, directions, euler = [], [], []
    for i, e in enumerate(eulers):
        e = np.asarray(e, dtype=np.float64)
        if e.ndim != 2 or e.shape[1] != 141:
            raise ValueError(f"euler_takes: eulers[{i}] must be (T, 141) degrees, got shape {e.shape}")
        motion = Motion(skeleton, expand_subset(e, "spine_neck_141", skeleton), fps)
        full = motion.positions()  # (T, 75, 3) cm
        positions.append(full[:, joints])
        directions.append(positions_to_directions(beat_to_ted43(motion), np.asarray(TED_BONES)))
        euler.append(e)
    return Takes(positions=positions, directions=directions, euler=euler)


def delayed(euler: np.ndarray, frames: int) -> np.ndarray:
    """``euler`` played ``frames`` frames late: the first frame repeated, the end cut (same length).

    >>> delayed(np.arange(5.0)[:, None], 2)[:, 0].tolist()
    [0.0, 0.0, 0.0, 1.0, 2.0]
    """
    x = np.asarray(euler)
    if frames < 0:
        raise ValueError(f"delayed: frames must be >= 0, got {frames}")
    if frames == 0:
        return x.copy()
    frames = min(frames, len(x))
    return np.concatenate([np.repeat(x[:1], frames, axis=0), x[: len(x) - frames]])


def perturbed_systems(
    eulers: list[np.ndarray], *, jitter_deg: float = 2.0, delay_frames: int = FPS, seed: int = 6
) -> dict[str, list[np.ndarray]]:
    """The six systems of :data:`SYSTEMS`, each a list of (T_k, 141) Euler tracks like ``eulers``.

    Parameters
    ----------
    eulers : list of (T_k, 141) float, degrees
        The ground-truth takes.
    jitter_deg : float
        Standard deviation of the white noise of ``"jitter"``, degrees.
    delay_frames : int
        Delay of ``"delayed 1 s"`` (15 frames = 1 s at 15 fps).
    seed : int
        Seed of the noise.

    Returns
    -------
    dict name -> list of (T_k, 141) float64, keys in :data:`SYSTEMS` order.

    Examples
    --------
    >>> takes = [np.arange(8.0)[:, None] * np.ones((1, 141)), np.zeros((6, 141))]
    >>> systems = perturbed_systems(takes)
    >>> systems["half range"][0][:, 0].tolist()  # mean 3.5 + half of the distance to it
    [1.75, 2.25, 2.75, 3.25, 3.75, 4.25, 4.75, 5.25]
    >>> systems["another take"][0].shape, float(systems["frozen mean pose"][0][0, 0])
    ((8, 141), 3.5)
    """
    eulers = [np.asarray(e, dtype=np.float64) for e in eulers]
    if not eulers:
        raise ValueError("perturbed_systems: no takes")
    rng = np.random.default_rng(seed)
    n = len(eulers)
    means = [e.mean(axis=0, keepdims=True) for e in eulers]
    return {
        "ground truth": eulers,
        "jitter": [e + rng.normal(0, jitter_deg, e.shape) for e in eulers],
        "half range": [m + 0.5 * (e - m) for e, m in zip(eulers, means)],
        "delayed 1 s": [delayed(e, delay_frames) for e in eulers],
        "another take": [np.resize(eulers[(i + 1) % n], e.shape) for i, e in enumerate(eulers)],
        "frozen mean pose": [np.repeat(m, len(e), axis=0) for e, m in zip(eulers, means)],
    }


def subset_spread(
    system: Takes,
    truth: Takes,
    semantic: list[np.ndarray],
    *,
    n_subsets: int = 30,
    n_clips: int = 10,
    length: int = WINDOW_LENGTH,
    stride: int = WINDOW_STRIDE,
    seed: int = 100,
) -> tuple[np.ndarray, np.ndarray]:
    """SRGR (paper variant) and L1 diversity (Euler) of a system over random subsets of clips.

    BEAT's Figure 6 argues that SRGR varies less than L1 diversity across evaluation samples.
    The clips are the ``length``-frame windows (every ``stride`` frames) of all takes; subset
    ``r`` is ``n_clips`` of them drawn without replacement with ``numpy.random.default_rng(seed + r)``.

    Parameters
    ----------
    system, truth : Takes
        The system's and the ground truth's takes (``positions``; the system's ``euler`` too).
    semantic : list of (T_k,) float
        Per-frame semantic scores (SRGR's weights).
    n_subsets, n_clips, length, stride, seed : int

    Returns
    -------
    srgr : (n_subsets,) float64
    l1div : (n_subsets,) float64, degrees summed over 141 channels

    Examples
    --------
    Skipped by the doctests (needs test takes); notebook 04 calls it per system:

    >>> srgr, l1 = subset_spread(systems["jitter"], gt, semantic)  # doctest: +SKIP
    >>> srgr.std() / srgr.mean(), l1.std() / l1.mean()  # coefficients of variation  # doctest: +SKIP
    """
    from beatlite.data.windows import window_starts
    from beatlite.metrics.recall import srgr
    from beatlite.metrics.variation import l1_diversity

    if system.euler is None:
        raise ValueError("subset_spread: the system needs its Euler tracks (L1 diversity)")
    clips = [(k, int(a)) for k, e in enumerate(system.euler) for a in window_starts(len(e), length, stride)]
    if len(clips) < n_clips:
        raise ValueError(f"subset_spread: {len(clips)} clips of {length} frames, need at least {n_clips}")
    srgr_values, l1_values = np.zeros(n_subsets), np.zeros(n_subsets)
    for r in range(n_subsets):
        pick = np.random.default_rng(seed + r).choice(len(clips), size=n_clips, replace=False)
        chosen = [clips[i] for i in pick]
        cut = [slice(a, a + length) for _, a in chosen]
        ks = [k for k, _ in chosen]
        srgr_values[r] = srgr(
            [system.positions[k][s] for k, s in zip(ks, cut)],
            [truth.positions[k][s] for k, s in zip(ks, cut)],
            [semantic[k][s] for k, s in zip(ks, cut)],
        )
        l1_values[r] = l1_diversity([system.euler[k][s] for k, s in zip(ks, cut)])
    return srgr_values, l1_values


def shifted_beat_align(
    audio_beats: list[np.ndarray],
    positions: list[np.ndarray],
    fps: float = FPS,
    *,
    sigma: float = 0.3,
    n_shifts: int = 20,
    margin: int = 8,
    seed: int = 0,
) -> tuple[float, float]:
    """BeatAlign of the motion and of the same motion shifted in time: is the alignment better than chance?

    Each take's positions are shifted circularly (``numpy.roll`` along time, so the amount of
    motion is unchanged) by ``n_shifts`` random offsets in ``[margin, T - margin)`` frames, drawn
    take by take from one ``numpy.random.default_rng(seed)``; the shifted score is the mean of
    :func:`beatlite.metrics.beat_align` over all shifted copies.

    Parameters
    ----------
    audio_beats : list of (A_k,) float, seconds
        Each take's audio onsets (:func:`beatlite.metrics.audio_beats`).
    positions : list of (T_k, J, 3) float, cm
        The joints to score (e.g. the two wrists).
    fps, sigma : float
        Frame rate and BeatAlign's Gaussian width (s).
    n_shifts, margin, seed : int

    Returns
    -------
    (true, shifted) : float, float
        Mean BeatAlign over takes of the real timing and of the shifted copies.

    Examples
    --------
    Clicks every 0.8 s and a joint that turns every 0.8 s, 1 frame (0.067 s) after each
    click: the real timing scores far above copies shifted by 3 to 8 frames.

    >>> sr, fps = 16000, 15
    >>> beats = [np.arange(0.8, 8.0, 0.8) - 0.032]
    >>> frames = np.arange(120)
    >>> pos = np.zeros((120, 1, 3))
    >>> pos[:, 0, 0] = 10 * np.cos(np.pi * (frames - 1) / 12)
    >>> true, shifted = shifted_beat_align(beats, [pos], fps, sigma=0.1, margin=3)
    >>> bool(true > shifted + 0.2)
    True
    """
    from beatlite.metrics.alignment import beat_align

    if len(audio_beats) != len(positions):
        raise ValueError(
            f"shifted_beat_align: {len(audio_beats)} audio takes but {len(positions)} motion takes"
        )
    rng = np.random.default_rng(seed)
    true, shifted = [], []
    for a, p in zip(audio_beats, positions):
        p = np.asarray(p)
        if len(p) <= 2 * margin:
            raise ValueError(
                f"shifted_beat_align: a take of {len(p)} frames is too short for margin {margin}"
            )
        true.append(beat_align(None, SR, p, fps, sigma=sigma, audio_beats=a))
        offsets = rng.integers(margin, len(p) - margin, size=n_shifts)
        shifted.append(
            np.mean(
                [
                    beat_align(None, SR, np.roll(p, int(d), axis=0), fps, sigma=sigma, audio_beats=a)
                    for d in offsets
                ]
            )
        )
    return float(np.nanmean(true)), float(np.nanmean(shifted))
