"""Tests of BeatAlign (BEAT) and Beat Consistency (HA2G) on synthetic click tracks and sinusoids."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from beatlite.metrics import audio_beats, beat_align, beat_consistency, gaussian_alignment
from beatlite.metrics.alignment import REFERENCE_COLUMNS_141, VARIANTS, BeatAlignVariant, motion_beat_times
from beatlite.metrics.beats import (
    alignment_score,
    angle_change_beats,
    angle_change_curve,
    append_palm_normals,
    euler_speed,
    local_minima,
    mean_angle_change,
    nearest_distance,
)
from beatlite.metrics.consistency import BCVariant, clip_audio_beats

SR = 16000
FPS = 15.0
PERIOD = 0.8  # s = 12 frames = 25 hops of 512 samples
HOP_S = 512 / SR  # 0.032 s
# onset_strength peaks up to ~1.25 hop after a click (librosa's framing); beats are never early.
LATE = 0.04


def click_track(times, duration, sr=SR):
    """Short 1 kHz clicks (10 ms, decaying) at ``times`` seconds."""
    y = np.zeros(int(duration * sr), np.float32)
    n = int(0.01 * sr)
    click = (np.hanning(2 * n)[n:] * np.sin(2 * np.pi * 1000 * np.arange(n) / sr) * 0.8).astype(np.float32)
    for t in times:
        i = int(round(t * sr))
        y[i : i + n] += click[: len(y) - i]
    return y


CLICKS = np.arange(1, 13) * PERIOD  # 0.8 .. 9.6 s
AUDIO = click_track(CLICKS, 10.0)


def swinging_joint(shift_s=0.0, duration=11.0):
    """(T, 1, 3) positions: x = 10 cos(pi (t - shift) / P) cm -> speed minima at t = k P + shift."""
    t = np.arange(int(duration * FPS)) / FPS
    p = np.zeros((len(t), 1, 3))
    p[:, 0, 0] = 10 * np.cos(np.pi * (t - shift_s) / PERIOD)
    return p


# ----------------------------------------------------------------------------- pieces
def test_gaussian_alignment_hand_computed():
    # audio [1.0, 2.0], motion [1.1, 2.5]: distances 0.1 and 0.5, sigma 0.3
    expected = (math.exp(-0.01 / 0.18) + math.exp(-0.25 / 0.18)) / 2
    assert gaussian_alignment([1.0, 2.0], [1.1, 2.5], 0.3) == pytest.approx(expected)
    assert gaussian_alignment([1.0, 2.0], [2.0, 1.0], 0.3) == 1.0  # coinciding beats
    assert gaussian_alignment([1.0], [], 0.3) == 0.0
    assert math.isnan(gaussian_alignment([], [1.0], 0.3))


def test_nearest_distance_matches_a_loop():
    rng = np.random.default_rng(0)
    q, r = rng.uniform(0, 100, 300), rng.uniform(0, 100, 77)
    loop = np.array([min(abs(a - b) for b in r) for a in q])
    np.testing.assert_allclose(nearest_distance(q, r), loop)


def test_alignment_directions():
    a, m = np.array([1.0]), np.array([1.0, 5.0])
    assert alignment_score(a, m, 0.3, "audio_to_motion") == 1.0  # extra motion beat ignored
    # motion -> audio: (1 + exp(-16 / 0.18)) / 2
    assert alignment_score(a, m, 0.3, "motion_to_audio") == pytest.approx((1 + math.exp(-16 / 0.18)) / 2)
    with pytest.raises(ValueError, match="direction"):
        alignment_score(a, m, 0.3, "both")


def test_local_minima_matches_scipy_argrelextrema():
    from scipy.signal import argrelextrema

    x = np.random.default_rng(1).normal(size=500)
    for order in (1, 2, 7):
        np.testing.assert_array_equal(local_minima(x, order), argrelextrema(x, np.less, order=order)[0])


def test_audio_beats_find_the_clicks():
    a = audio_beats(AUDIO, SR)
    assert len(a) == len(CLICKS)
    assert np.all(a - CLICKS >= -1e-9) and np.all(a - CLICKS <= LATE)


def test_audio_beats_legacy_sr_scales_times():
    # librosa's default 22050 Hz used for 16 kHz audio: times x 16000 / 22050 = 0.7256
    a = audio_beats(AUDIO, SR, legacy_sr=True)
    assert len(a) == len(CLICKS)
    np.testing.assert_allclose(a * 22050 / 16000, CLICKS, atol=LATE * 22050 / 16000 + 1e-9)


def test_audio_beats_backtrack_moves_earlier():
    plain = audio_beats(AUDIO, SR)
    for mode in ("rms", "onset"):
        back = audio_beats(AUDIO, SR, backtrack=mode)
        assert len(back) == len(plain) and np.all(back <= plain)


# ----------------------------------------------------------------------------- BeatAlign
def test_motion_beats_of_a_swinging_joint():
    m = motion_beat_times(swinging_joint(), FPS)[0]
    np.testing.assert_allclose(m, np.arange(1, 14) * PERIOD, atol=1e-9)  # 11 s of motion


def test_beat_align_is_one_when_beats_coincide():
    score = beat_align(AUDIO, SR, swinging_joint(), FPS)
    assert score >= math.exp(-(LATE**2) / (2 * 0.3**2)) and score <= 1.0


def test_beat_align_decreases_with_offset_as_the_gaussian():
    scores = []
    for n in range(0, 6):  # motion beats n frames *early*: distance d + (detection delay in [0, LATE])
        d = n / FPS
        s = beat_align(AUDIO, SR, swinging_joint(-d), FPS)
        assert math.exp(-((d + LATE) ** 2) / 0.18) - 1e-9 <= s <= math.exp(-(d**2) / 0.18) + 1e-9
        scores.append(s)
    assert all(a > b for a, b in zip(scores, scores[1:]))


def test_beat_align_exact_value_with_onset_backtracking():
    # clicks on hop boundaries (0.8 s = 25 hops) are found exactly when backtracked to the envelope minimum;
    # motion 2 frames early: d = 2/15 s -> exp(-d^2 / (2 * 0.3^2)) = exp(-0.017778 / 0.18) = 0.90596
    a = audio_beats(AUDIO, SR, backtrack="onset")
    np.testing.assert_allclose(a, CLICKS, atol=1e-9)
    s = beat_align(AUDIO, SR, swinging_joint(-2 / FPS), FPS, variant=BeatAlignVariant(backtrack="onset"))
    assert s == pytest.approx(math.exp(-((2 / 15) ** 2) / 0.18), rel=1e-9)


def test_beat_align_frozen_pose_scores_zero_and_lists_average():
    frozen = np.repeat(swinging_joint()[:1], 165, axis=0)
    assert beat_align(AUDIO, SR, frozen, FPS) == 0.0
    both = beat_align([AUDIO, AUDIO], SR, [swinging_joint(), frozen], FPS)
    assert both == pytest.approx(beat_align(AUDIO, SR, swinging_joint(), FPS) / 2)


EULER = BeatAlignVariant(motion_kind="euler")


def test_precomputed_audio_beats_give_the_same_scores():
    beats = VARIANTS["beatlite"].audio_beats(AUDIO, SR)
    direct = beat_align(AUDIO, SR, swinging_joint(-1 / FPS), FPS)
    assert beat_align(None, SR, swinging_joint(-1 / FPS), FPS, audio_beats=beats) == direct
    bc = _bc(AUDIO, rotating_bone(-1 / FPS))
    variant = BCVariant(pairs=((0, 1),), palm_normals=False)
    assert beat_consistency(None, SR, rotating_bone(-1 / FPS), FPS, variant=variant, audio_beats=beats) == bc
    with pytest.raises(ValueError, match="clip variant"):
        clips = BCVariant(pairs=((0, 1),), palm_normals=False, clip_length=34)
        beat_consistency(None, SR, rotating_bone(), FPS, variant=clips, audio_beats=beats)


def test_precomputed_clip_onsets_give_the_same_clip_bc():
    """``clip_audio_beats`` detects each 34-frame clip's onsets once; passed back they give the same score."""
    clips = BCVariant(pairs=((0, 1),), palm_normals=False, clip_length=34)
    motion = rotating_bone(-1 / FPS)
    direct = beat_consistency(AUDIO, SR, motion, FPS, variant=clips)
    beats = clip_audio_beats(AUDIO, SR, len(motion), FPS, variant=clips)
    assert len(beats) == len(range(0, len(motion) - 34 + 1, 10)) and np.isfinite(direct)
    assert beat_consistency(None, SR, motion, FPS, variant=clips, audio_beats=beats) == direct
    assert beat_consistency(None, SR, [motion], FPS, variant=clips, audio_beats=[beats]) == direct


def test_euler_motion_beats_hand_computed():
    # column 36 = [0, 3, 5, 6, 8, 11, 15]: forward differences 3, 2, 1, 2, 3, 4 (x 15 fps);
    # index 2 is below its 2 neighbours on each side -> one beat at 2/15 s
    ch = np.zeros((7, 141))
    ch[:, 36] = [0, 3, 5, 6, 8, 11, 15]
    np.testing.assert_allclose(euler_speed(ch, [36, 37, 38], 15)[:, 0], np.array([3, 2, 1, 2, 3, 4]) * 15.0)
    beats = motion_beat_times(ch, 15, variant=EULER)
    assert len(beats) == 1
    np.testing.assert_allclose(beats[0], [2 / 15])


def test_reference_columns_are_the_ring_finger_triplet_of_the_30_39_slice():
    assert REFERENCE_COLUMNS_141 == (36, 37, 38)  # 30:39[6:9], "beat_right_wrist" in the reference
    t = np.arange(165) / FPS
    wave = 10 * np.cos(np.pi * t / PERIOD)
    in_slice = np.zeros((165, 141))
    in_slice[:, 36] = wave
    arm_only = np.zeros((165, 141))
    arm_only[:, 9:18] = wave[:, None]  # the real right shoulder/arm/forearm of spine_neck_141
    assert motion_beat_times(in_slice, FPS, variant=EULER)[0].size > 0
    assert motion_beat_times(arm_only, FPS, variant=EULER)[0].size == 0
    whole_take = dataclasses.replace(VARIANTS["reference"], window=(0.0, 500.0))
    assert beat_align(AUDIO, SR, arm_only, FPS, variant=whole_take) == 0.0


def _beat_reference_formula(y, euler, t_start=10, t_end=500, sigma=0.3, order=2, fps=15):
    """BEAT's BeatAlign as utils/metric.py (class ``alignment``) computes it, written out with librosa and scipy only:
    onset strength of the 16 kHz audio of [t_start, t_end) s, ``onset_detect`` and ``frames_to_time`` at librosa's
    default rate, onsets backtracked to RMS minima; the L2 speed (forward differences) of columns 30:39 of the pose,
    third triplet; ``argrelextrema`` minima of order 2 in frames [t_start fps, t_end fps); the mean over audio beats
    of exp(-d^2 / (2 sigma^2)) to the nearest motion beat."""
    import librosa
    from scipy.signal import argrelextrema

    short = y[t_start * SR : t_end * SR]
    envelope = librosa.onset.onset_strength(y=short, sr=SR)
    raw = librosa.onset.onset_detect(onset_envelope=envelope, backtrack=False)
    rms = librosa.feature.rms(S=np.abs(librosa.stft(y=short)))
    audio_times = librosa.frames_to_time(librosa.onset.onset_backtrack(raw, rms[0]))
    slice_ = np.asarray(euler, dtype=np.float64)[:, 30:39]
    velocity = slice_[1:] - slice_[:-1]
    speed = np.linalg.norm(velocity[:, 6:9], axis=1)
    motion_times = argrelextrema(speed[t_start * fps : t_end * fps], np.less, order=order)[0] / fps
    nearest = [min(abs(m - a) for m in motion_times) for a in audio_times]
    return sum(math.exp(-(d**2) / (2 * sigma**2)) for d in nearest) / len(audio_times)


def test_reference_beat_align_equals_beats_code_written_out():
    """BeatAlign (reference) on 30 s of irregular clicks in noise and a random-walk Euler pose whose columns 36:39
    swing: the value of BEAT's code written out independently (above), to rounding."""
    rng = np.random.default_rng(0)
    clicks = np.cumsum(rng.uniform(0.35, 1.1, 60))
    audio = click_track(clicks[clicks < 29.5], 30.0) + 0.003 * rng.standard_normal(30 * SR).astype(np.float32)
    t = np.arange(30 * int(FPS)) / FPS
    euler = 0.2 * rng.normal(0.0, 5.0, (len(t), 141)).cumsum(axis=0)
    euler[:, 36:39] += np.outer(20 * np.sin(2 * np.pi * t / 1.3), [1.0, 0.5, 0.2])
    want = _beat_reference_formula(audio, euler)
    assert beat_align(audio, SR, euler, FPS, variant="reference") == pytest.approx(want, rel=1e-12)
    assert 0.5 < want < 1.0


def test_window_makes_times_relative_to_its_start():
    full = motion_beat_times(swinging_joint(), FPS)[0]
    cut = motion_beat_times(swinging_joint(), FPS, variant=BeatAlignVariant(window=(1.6, 8.0)))[0]
    inside = full[(full > 1.6 + 1e-9) & (full < 8.0 - 1e-9)] - 1.6
    # frames [24, 120) are searched; 1.6 s itself is the first sample (never a minimum): beats 2.4 .. 7.2 s
    np.testing.assert_allclose(cut, inside, atol=1e-9)
    np.testing.assert_allclose(cut, np.arange(1, 8) * PERIOD, atol=1e-9)


def test_beat_align_errors():
    with pytest.raises(ValueError, match="motion_kind"):
        beat_align(AUDIO, SR, swinging_joint(), FPS, variant=BeatAlignVariant(motion_kind="quaternions"))
    with pytest.raises(ValueError, match="variant must be one of"):
        beat_align(AUDIO, SR, swinging_joint(), FPS, variant="legacy")
    with pytest.raises(ValueError, match=r"motion must be 3-D, got shape \(10, 4\)"):
        beat_align(AUDIO, SR, np.zeros((10, 4)), FPS)
    with pytest.raises(ValueError, match="lists of equal length"):
        beat_align([AUDIO], SR, swinging_joint(), FPS)


# ----------------------------------------------------------------------------- HA2G BC
def test_angle_change_curve_hand_computed():
    # two vectors, angle 90, 45, 45, 90 deg -> theta/pi = .5, .25, .25, .5; |diffs| .25, 0, .25;
    # MAAC = 0.5 / 3 = 1/6; c = [0, 1.5, 0, 1.5]
    ang = np.radians([90, 45, 45, 90])
    d = np.zeros((4, 2, 3))
    d[:, 0, 0] = 1
    d[:, 1, 0], d[:, 1, 1] = np.cos(ang), np.sin(ang)
    pairs = np.array([[0, 1]])
    ca = mean_angle_change(d, pairs)
    np.testing.assert_allclose(ca, [1 / 6])
    np.testing.assert_allclose(angle_change_curve(d, pairs, ca), [0, 1.5, 0, 1.5], atol=1e-12)


def test_angle_change_beats_hand_computed():
    # t in [2, 7]: t=3 (0.49 between 0.5 and 0.51) drops only 0.01/0.02 < 0.03 -> no beat;
    # t=6 (0.3 between 0.9 and 0.8) -> beat at 6/15 = 0.4 s
    c = np.array([0, 1, 0.5, 0.49, 0.51, 0.9, 0.3, 0.8, 1.0])
    np.testing.assert_allclose(angle_change_beats(c, 15), [0.4])


def test_palm_normals():
    d = np.zeros((1, 42, 3))
    d[0, :, 0] = 1
    d[0, 11], d[0, 17] = [1, 0, 0], [0, 2, 0]  # left palm = cross(v11, v17) -> +z
    d[0, 28], d[0, 34] = [0, 1, 0], [1, 0, 0]  # right palm = cross(v28, v34) -> -z
    out = append_palm_normals(d)
    assert out.shape == (1, 44, 3)
    np.testing.assert_allclose(out[0, 42:], [[0, 0, 1], [0, 0, -1]])


def rotating_bone(shift_s=0.0, duration=11.0):
    """(T, 2, 3) vectors whose included angle is pi/4 + 0.5 cos(pi (t - t0) / P), with its turning
    points half a frame before k P + shift, so the backward-difference angle change has strict
    minima exactly at frames k P + shift."""
    t = np.arange(int(duration * FPS)) / FPS
    theta = np.pi / 4 + 0.5 * np.cos(np.pi * (t - shift_s + 0.5 / FPS) / PERIOD)
    d = np.zeros((len(t), 2, 3))
    d[:, 0, 0] = 1
    d[:, 1, 0], d[:, 1, 1] = np.cos(theta), np.sin(theta)
    return d


def _bc(audio, dirs, change_angle=None, **kw):
    variant = BCVariant(pairs=((0, 1),), palm_normals=False, **kw)
    return beat_consistency(audio, SR, dirs, FPS, change_angle=change_angle, variant=variant)


def test_bc_is_one_when_beats_coincide_and_decreases_with_offset():
    aligned = _bc(AUDIO, rotating_bone())
    assert aligned >= math.exp(-(LATE**2) / (2 * 0.1**2))
    scores = [aligned]
    for n in range(1, 4):
        d = n / FPS
        s = _bc(AUDIO, rotating_bone(-d))
        assert math.exp(-((d + LATE) ** 2) / 0.02) - 1e-9 <= s <= math.exp(-(d**2) / 0.02) + 1e-9
        scores.append(s)
    assert all(a > b for a, b in zip(scores, scores[1:]))


def test_bc_exact_value_with_onset_backtracking():
    # motion beats 1 frame early: d = 1/15 s, sigma 0.1 -> exp(-d^2 / 0.02) = exp(-0.22222) = 0.80074
    s = _bc(AUDIO, rotating_bone(-1 / FPS), backtrack="onset")
    assert s == pytest.approx(math.exp(-((1 / 15) ** 2) / 0.02), rel=1e-9)


def test_bc_clip_protocol_runs_and_stays_high_when_aligned():
    s = _bc(AUDIO, rotating_bone(), clip_length=34, clip_stride=10)
    assert s >= math.exp(-(LATE**2) / 0.02)
    frozen = np.repeat(rotating_bone()[:1], 165, axis=0)
    maac = mean_angle_change(rotating_bone(), np.array([[0, 1]]))  # "training" statistics
    assert math.isnan(_bc(AUDIO, frozen, change_angle=maac))  # no motion beat anywhere: nothing to score


def test_bc_default_pairs_come_from_the_ted_skeleton():
    from beatlite.metrics.beats import included_angles
    from beatlite.metrics.consistency import default_angle_pairs
    from beatlite.skeleton import ted

    pairs = default_angle_pairs()
    assert pairs.shape == (41, 2)  # HA2G's 41 pairs
    assert pairs.min() >= 0 and pairs.max() == 43  # 42 bones + 2 palm normals
    d = np.random.default_rng(0).normal(size=(5, 42, 3))
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    np.testing.assert_allclose(included_angles(append_palm_normals(d), pairs), ted.pair_angles(d) / np.pi)


# HA2G's hard-coded MAAC of its 41 angle pairs on TED Expressive (``change_angle`` in HA2G's
# scripts/train_expressive.py), in the order of beatlite.skeleton.ted.ANGLE_PAIRS.
HA2G_CHANGE_ANGLE = np.array(
    [
        0.0027804733254015446, 0.002761547453701496, 0.005953566171228886, 0.013764726929366589,
        0.022748252376914024, 0.039307352155447006, 0.03733552247285843, 0.03775784373283386,
        0.0485558956861496, 0.032914578914642334, 0.03800227493047714, 0.03757007420063019,
        0.027338404208421707, 0.01640886254608631, 0.003166505601257086, 0.0017252820543944836,
        0.0018696568440645933, 0.0016072227153927088, 0.005681346170604229, 0.013287615962326527,
        0.021516695618629456, 0.033936675637960434, 0.03094293735921383, 0.03378918394446373,
        0.044323261827230453, 0.034706637263298035, 0.03369896858930588, 0.03573163226246834,
        0.02628341130912304, 0.014071882702410221, 0.0029828345868736506, 0.0015706412959843874,
        0.0017107439925894141, 0.0014634154504165053, 0.004873405676335096, 0.002998138777911663,
        0.0030240598134696484, 0.0009890805231407285, 0.0012279648799449205, 0.047324635088443756,
        0.04472292214632034,
    ]
)  # fmt: skip
EAR_PAIR = 37  # (38, 40): nose->left eye vs left eye->left ear; bone 40 is in no other pair


def ear_swinging_skeleton(theta: np.ndarray, seed: int = 0) -> np.ndarray:
    """(T, 42, 3) fixed random unit bones, except bone 40 at angle ``pi theta_t`` from bone 38."""
    rng = np.random.default_rng(seed)
    base = rng.normal(size=(42, 3))
    base /= np.linalg.norm(base, axis=-1, keepdims=True)
    u = base[38]
    w = np.cross(u, [0.0, 0.0, 1.0])
    w /= np.linalg.norm(w)
    d = np.repeat(base[None], len(theta), axis=0)
    d[:, 40] = np.cos(np.pi * theta)[:, None] * u + np.sin(np.pi * theta)[:, None] * w
    return d


def test_angle_change_curve_with_ha2g_constants_hand_computed():
    # only pair 37 moves: theta/pi = .25, .30, .30, .20 -> |diffs| .05, 0, .10, divided by its
    # MAAC and averaged over HA2G's 41 pairs (none is rigid: smallest / largest MAAC = 0.02)
    from beatlite.metrics.consistency import default_angle_pairs, prepare_directions

    d = prepare_directions(ear_swinging_skeleton(np.array([0.25, 0.30, 0.30, 0.20])))
    ca = HA2G_CHANGE_ANGLE[EAR_PAIR]
    want = [0.0, 0.05 / ca / 41, 0.0, 0.10 / ca / 41]
    np.testing.assert_allclose(
        angle_change_curve(d, default_angle_pairs(), HA2G_CHANGE_ANGLE), want, rtol=1e-9
    )


# HA2G's 41 angle pairs over its 44 vectors (``angle_pair`` in HA2G's scripts/train_expressive.py), written out here
# rather than taken from beatlite.skeleton.ted, so that the oracle below shares no code with beatlite.
HA2G_ANGLE_PAIRS = (
    (0, 1), (0, 2), (1, 3), (3, 4), (5, 6), (6, 7), (8, 9), (9, 10), (11, 12), (12, 13), (14, 15), (15, 16),
    (17, 18), (18, 19), (17, 5), (5, 8), (8, 14), (14, 11), (2, 20), (20, 21), (22, 23), (23, 24), (25, 26),
    (26, 27), (28, 29), (29, 30), (31, 32), (32, 33), (34, 35), (35, 36), (34, 22), (22, 25), (25, 31), (31, 28),
    (0, 37), (37, 38), (37, 39), (38, 40), (39, 41), (4, 42), (21, 43),
)  # fmt: skip


def _ha2g_bc_formula(audio, dirs, change_angle, sigma=0.1, thres=0.03, length=34, stride=10):
    """HA2G's BC as its evaluator computes it (scripts/train_expressive.py, ``evaluate_testset``), written out with
    NumPy and librosa only: per 34-frame clip (stride 10) the palm normals cross(v11, v17) and cross(v28, v34) of
    the bones, every one of the 44 vectors normalised, the 41 angles / pi, their summed |change| / MAAC / 41 (frame 0:
    0), beats at strict minima of frames 2..32 that drop >= ``thres`` to a neighbour, ``onset_detect(y, sr=16000,
    units="time")`` of the clip's audio as HA2G's loader cuts it (``floor(start / T * N)``, 36266 samples,
    symmetric-padded to 36267), clips weighted by their audio beats.

    Returns the score and the angle-change curve of every scored or skipped clip, (clips, 34)."""
    import librosa

    v = np.asarray(dirs, dtype=np.float64).reshape(len(dirs), 42, 3)
    palms = np.cross(v[:, [11, 28]], v[:, [17, 34]])
    vec = np.concatenate([v, palms], axis=1)
    vec = vec / np.linalg.norm(vec, axis=-1, keepdims=True)
    total = weight = 0.0
    curves = []
    for start in range(0, len(v) - length + 1, stride):
        a0 = math.floor(start / len(v) * len(audio))
        clip = audio[a0 : a0 + int(length / FPS * SR)]
        clip = np.pad(clip, (0, int(round(length / FPS * SR)) - len(clip)), mode="symmetric")
        w = vec[start : start + length]
        c = np.zeros(length)
        for p, (i, j) in enumerate(HA2G_ANGLE_PAIRS):
            angle = np.arccos(np.clip(np.einsum("ij,ij->i", w[:, i], w[:, j]), -1, 1)) / math.pi
            c[1:] += np.abs(angle[1:] - angle[:-1]) / change_angle[p] / len(change_angle)
        curves.append(c)
        beats = [
            t / 15.0
            for t in range(2, 33)
            if c[t] < c[t - 1] and c[t] < c[t + 1] and (c[t - 1] - c[t] >= thres or c[t + 1] - c[t] >= thres)
        ]
        if not beats:
            continue
        onsets = librosa.onset.onset_detect(y=clip, sr=16000, units="time")
        total += sum(math.exp(-min((a - m) ** 2 for m in beats) / (2 * sigma * sigma)) for a in onsets)
        weight += len(onsets)
    return total / weight, np.array(curves)


def every_bone_swinging(duration: float = 5.0, seed: int = 0) -> np.ndarray:
    """(T, 42, 3) unit bones, each turning about its own random axis by an angle of period 2 P, amplitude and phase
    of its own: every one of the 41 angle pairs (palm normals included) changes from frame to frame."""
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(seed)
    t = np.arange(int(duration * FPS)) / FPS
    base, axis = rng.normal(size=(2, 42, 3))
    amplitude, phase = rng.uniform(0.2, 0.6, 42), rng.uniform(0.0, 0.1, 42)
    angle = amplitude * np.cos(np.pi * (t[:, None] - phase) / PERIOD)
    axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
    bones = [Rotation.from_rotvec(axis[k] * angle[:, k : k + 1]).apply(base[k]) for k in range(42)]
    d = np.stack(bones, axis=1)
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def test_bc_legacy_with_ha2g_constants_equals_ha2g_formula():
    """BC (ha2g) against HA2G's evaluator written out independently (pairs, palm normals, normalisation, beats,
    onsets, weighting, audio cut): the same angle-change curve of every clip and the same score, to rounding."""
    from beatlite.metrics.consistency import default_angle_pairs, prepare_directions

    dirs = every_bone_swinging()
    audio = AUDIO[: int(5.0 * SR)]
    want, curves = _ha2g_bc_formula(audio, dirs, HA2G_CHANGE_ANGLE)
    vec = prepare_directions(dirs)
    for k, start in enumerate(range(0, len(dirs) - 34 + 1, 10)):
        got_curve = angle_change_curve(vec[start : start + 34], default_angle_pairs(), HA2G_CHANGE_ANGLE)
        np.testing.assert_allclose(got_curve, curves[k], rtol=1e-12, atol=1e-12)
    assert np.all(curves[:, 1:] > 0)  # every frame changes: a wrong pair or palm normal changes the curve
    got = beat_consistency(audio, SR, dirs, FPS, change_angle=HA2G_CHANGE_ANGLE, variant="ha2g")
    assert got == pytest.approx(want, rel=1e-12)
    assert 0.5 < got <= 1.0


def rigid_pair_skeleton(duration: float = 11.0) -> np.ndarray:
    """(T, 3, 3): :func:`rotating_bone`'s pair plus a third vector rigidly at 1 rad from vector 0,
    all turned by a slowly varying global rotation, so the rigid pair's angle moves only by
    round-off (MAAC ~ 1e-17)."""
    from scipy.spatial.transform import Rotation

    d = rotating_bone(duration=duration)
    t = np.arange(d.shape[0]) / FPS
    third = np.repeat([[np.cos(1.0), 0.0, np.sin(1.0)]], d.shape[0], axis=0)
    v = np.concatenate([d, third[:, None]], axis=1)
    rot = Rotation.from_rotvec(np.outer(0.3 * np.sin(2 * np.pi * t / 7.0), [0.2, 0.5, 0.8]))
    return np.stack([rot.apply(v[:, k]) for k in range(3)], axis=1)


def test_bc_is_stable_when_a_rigid_pair_is_perturbed():
    # Without the rigid-pair rule the 1e-9 noise divided by a MAAC of ~1e-17 decides the beats:
    # the old code scored 0.893 unperturbed and 0.862 / 0.833 / 0.861 with three noise draws.
    pairs = np.array([[0, 1], [0, 2]])
    v = rigid_pair_skeleton()
    ca = mean_angle_change(v, pairs)
    assert ca[1] < 1e-12 * ca[0]  # the second pair is rigid
    kw = {"variant": BCVariant(pairs=((0, 1), (0, 2)), palm_normals=False), "change_angle": ca}
    clean = beat_consistency(AUDIO, SR, v, FPS, **kw)
    rng = np.random.default_rng(0)
    for _ in range(3):
        noisy = beat_consistency(AUDIO, SR, v + 1e-9 * rng.standard_normal(v.shape), FPS, **kw)
        assert abs(noisy - clean) < 0.005
    # the rigid pair is left out: the score is the moving pair's alone
    alone = BCVariant(pairs=((0, 1),), palm_normals=False)
    assert clean == beat_consistency(AUDIO, SR, v, FPS, variant=alone, change_angle=ca[:1])


def test_drop_rigid_pairs_threshold_is_relative():
    from beatlite.metrics.beats import drop_rigid_pairs

    pairs = np.array([[0, 1], [1, 2], [2, 3]])
    for scale in (1.0, 1e-6, 1e6):  # units do not matter
        p, ca = drop_rigid_pairs(pairs, scale * np.array([1e-2, 1e-8, 1e-5]))
        np.testing.assert_array_equal(p, [[0, 1], [2, 3]])
        np.testing.assert_allclose(ca, scale * np.array([1e-2, 1e-5]))
    assert len(drop_rigid_pairs(pairs, np.array([1e-2, 1e-8, 0.0]), rtol=0)[0]) == 2  # 0 keeps MAAC > 0
    with pytest.raises(ValueError, match="no moving pair"):
        drop_rigid_pairs(pairs, np.zeros(3))
    with pytest.raises(ValueError, match="one entry per pair"):
        drop_rigid_pairs(pairs, np.ones(2))
    with pytest.raises(ValueError, match=">= 0"):
        drop_rigid_pairs(pairs, np.array([1.0, -1.0, 1.0]))


# ----------------------------------------------------------------------------- librosa oracles
def test_stft_magnitude_equals_librosa():
    import librosa

    from beatlite.metrics.beats import stft_magnitude

    y = np.random.default_rng(0).normal(scale=0.1, size=50_001).astype(np.float32)
    ours = stft_magnitude(y, chunk=7)  # several chunks
    ref = np.abs(librosa.stft(y, n_fft=2048, hop_length=512))
    assert ours.shape == ref.shape
    np.testing.assert_allclose(ours, ref, atol=1e-4 * ref.max())


def test_audio_beats_librosa_peak_picking_equals_onset_detect():
    # HA2G's call: librosa.onset.onset_detect(y=clip, sr=16000, units="time")
    import librosa

    y = AUDIO + np.random.default_rng(1).normal(scale=0.003, size=AUDIO.shape).astype(np.float32)
    ref = librosa.onset.onset_detect(y=y, sr=SR, units="time")
    np.testing.assert_allclose(audio_beats(y, SR, peak_pick="librosa"), ref, atol=1e-9)


WORKER = """
import numpy as np
from beatlite.metrics.beats import audio_beats
y = (0.1 * np.sin(np.arange(32000) * 0.05) * (np.arange(32000) % 8000 < 800)).astype(np.float32)
print(len(audio_beats(y, 16000, peak_pick="librosa", backtrack="rms")), len(audio_beats(y, 16000)))
"""


@pytest.mark.slow
def test_workers_started_after_warm_up_detect_onsets_from_a_fresh_numba_cache(tmp_path):
    """Fresh processes compiling librosa's numba code at once can corrupt numba's cache (numba#10128): warm_up
    compiles it once in the parent; three workers started together on that cache then all detect onsets."""
    import os
    import subprocess
    import sys

    env = {
        **os.environ,
        "NUMBA_CACHE_DIR": str(tmp_path / "numba"),
    }  # an empty cache, as in a fresh environment
    warm = subprocess.run([sys.executable, "-c", "from beatlite.metrics.beats import warm_up; warm_up()"],
                          env=env, capture_output=True, text=True, timeout=600)  # fmt: skip
    assert warm.returncode == 0, warm.stderr
    assert any((tmp_path / "numba").rglob("*.nbi")), "warm_up left no compiled code in the cache"
    workers = [subprocess.Popen([sys.executable, "-c", WORKER], env=env, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True) for _ in range(3)]  # fmt: skip
    outs = [w.communicate(timeout=600) for w in workers]
    for w, (_, err) in zip(workers, outs, strict=True):
        assert w.returncode == 0, err[-3000:]
    assert len({out for out, _ in outs}) == 1  # the same onsets in every worker
