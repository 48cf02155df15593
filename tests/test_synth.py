"""Unit tests of :mod:`beatlite.synth` (the generator of ``data_samples/``)."""

from __future__ import annotations

import shutil
import sys
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from childproc import run_ok

from beatlite.io import parse_take_name, read_bvh, read_semantic, read_textgrid
from beatlite.skeleton.beat import beat_skeleton
from beatlite.skeleton.rotations import euler_to_matrix, matrix_to_euler
from beatlite.synth import (
    EMOTION_STYLES,
    SEMANTIC_SCORES,
    SPEAKERS,
    EspeakNotFoundError,
    TakeSpec,
    corpus_specs,
    generate_take,
)
from beatlite.synth.motion import continuous_euler, min_jerk, smooth_box, two_bone_ik
from beatlite.synth.plan import Beat, Plan, TimedWord, make_plan, semantic_segments
from beatlite.synth.speech import espeak_path, split_phonemes, trim_silence

needs_espeak = pytest.mark.skipif(shutil.which("espeak-ng") is None, reason="espeak-ng not installed")


# ----------------------------------------------------------------------------- speech helpers
@pytest.mark.parametrize(
    ("text", "phones"),
    [
        ("s'3:k@L", ("s", "3:", "k", "@L")),  # circle
        ("h@l'oU", ("h", "@", "l", "oU")),  # hello
        ("t'2aIm", ("t", "aI", "m")),  # time: the stress digit is dropped
        ("f'ju:tS3", ("f", "j", "u:", "tS", "3")),  # future
    ],
)
def test_split_phonemes(text: str, phones: tuple[str, ...]) -> None:
    assert split_phonemes(text) == phones


def test_trim_silence_keeps_the_loud_part_plus_margins() -> None:
    y = np.zeros(22050, dtype=np.float32)
    y[1000:3000] = 0.5  # 2000 loud samples
    out = trim_silence(y, threshold=0.02, margin_s=0.005)
    margin = round(0.005 * 22050)  # 110 samples each side
    assert out.size == 2000 + 2 * margin
    with pytest.raises(ValueError, match="1-D"):
        trim_silence(np.zeros((4, 2)))


def test_missing_espeak_names_the_install_command(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("PATH", "/nonexistent")
    with pytest.raises(EspeakNotFoundError, match="apt-get install espeak-ng"):
        espeak_path()


# ----------------------------------------------------------------------------- time profiles
def test_min_jerk_has_zero_speed_at_both_ends() -> None:
    x = np.array([0.0, 0.5, 1.0])
    assert np.allclose(min_jerk(x), [0.0, 0.5, 1.0])  # 10/8 - 15/16 + 6/32 = 0.5
    h = 1e-4
    assert abs((min_jerk(np.array([h]))[0] - 0.0) / h) < 1e-6  # derivative 30x^2(1-x)^2 -> 0
    assert abs((1.0 - min_jerk(np.array([1 - h]))[0]) / h) < 1e-6
    assert np.allclose(min_jerk(np.array([-1.0, 2.0])), [0.0, 1.0])  # clipped


def test_smooth_box_is_one_inside_and_zero_outside() -> None:
    t = np.array([0.0, 0.5, 1.0, 1.5, 2.0, 2.25, 2.5, 3.0])
    w = smooth_box(t, start=1.0, end=2.0, ramp_in=0.5, ramp_out=0.5)
    assert np.allclose(w[[0, 1]], 0.0) and np.allclose(w[[2, 3, 4]], 1.0)
    assert w[5] == pytest.approx(0.5)  # half-way down the minimum-jerk ramp
    assert np.allclose(w[[6, 7]], 0.0)


def test_beat_loop_speed_is_zero_only_at_the_beats() -> None:
    from beatlite.synth.motion import beat_lift

    plan = Plan(
        words=(),
        phrases=(),
        beats=(Beat(1.0, 5.0, 0.45, 0.45), Beat(1.5, 4.0, 0.45, 0.45)),
        gestures=(),
        duration=3.0,
    )
    fs = 1200
    t = np.arange(0, 3.0, 1 / fs)
    lift, loop = beat_lift(t, plan)
    speed = np.hypot(np.gradient(lift), np.gradient(loop)) * fs
    for b in plan.beats:
        i = int(round(b.time * fs))
        assert lift[i] == pytest.approx(0.0, abs=1e-9) and loop[i] == pytest.approx(0.0, abs=1e-9)
    # loop 1 on [0.1, 1.0] (0.9 s: full size), loop 2 on [1.0, 1.5] (0.5 s: A = 4 * sqrt(0.5 / 0.9))
    # top of a circle of diameter A at mid-loop: lift = A
    assert lift[int(0.55 * fs)] == pytest.approx(5.0, rel=1e-3)
    assert lift[int(1.25 * fs)] == pytest.approx(4.0 * np.sqrt(0.5 / 0.9), rel=1e-3)
    # circle + phase rate 2 pi (1 - cos 2 pi s) / D: speed = (A / 2) 2 pi (1 - cos 2 pi s) / D,
    # peak (s = 0.5) = 2 pi A / D = 2 pi 5 / 0.9 = 34.9 cm/s
    assert speed[int(0.55 * fs)] == pytest.approx(2 * np.pi * 5.0 / 0.9, rel=1e-3)
    # the only local minima of the speed inside the loops are the beats (no stop at the top)
    inner = speed[int(0.1 * fs) + 2 : int(1.5 * fs) - 2]
    minima = np.flatnonzero((inner[1:-1] < inner[:-2]) & (inner[1:-1] <= inner[2:])) + 1
    times = (minima + int(0.1 * fs) + 2) / fs
    assert np.allclose(times, [1.0], atol=2 / fs), times


def test_loop_accents_are_shallow_speed_minima() -> None:
    from beatlite.synth.motion import loop_phase
    from beatlite.synth.plan import ACCENT_DEPTH

    fs = 2000
    t = np.arange(0.0, 1.0 + 0.5 / fs, 1 / fs)
    phi = loop_phase(t, 0.0, 1.0, (0.4,))
    assert phi[0] == 0.0 and phi[-1] == pytest.approx(2 * np.pi)
    rate = np.gradient(phi) * fs
    assert np.all(np.diff(phi) >= 0)  # monotone: the hand never turns back
    minima = np.flatnonzero((rate[1:-1] < rate[:-2]) & (rate[1:-1] <= rate[2:])) + 1
    assert np.allclose(minima / fs, [0.4], atol=2 / fs)
    # the rate profile is 1 at each piece's middle, ACCENT_DEPTH at the accent, 0 at the ends
    mid1, mid2 = rate[int(0.2 * fs)], rate[int(0.7 * fs)]
    assert rate[int(0.4 * fs)] / mid1 == pytest.approx(ACCENT_DEPTH, rel=0.01)
    assert mid1 == pytest.approx(mid2, rel=0.01)
    assert rate[0] == pytest.approx(0.0, abs=1e-3 * mid1)


def test_speech_onsets_find_clicks() -> None:
    from beatlite.synth.onsets import HOP, N_FFT, speech_onsets

    sr = 16000
    y = np.zeros(3 * sr)
    clicks = (0.5, 1.3, 2.1)
    rng = np.random.default_rng(0)
    for c in clicks:  # 100 ms noise bursts
        i = int(c * sr)
        y[i : i + 1600] = 0.5 * rng.normal(size=1600)
    found = speech_onsets(y, sr)
    # the largest flux comes from the first centred frame that sees the burst, up to half a window
    # (N_FFT / 2 = N_FFT // (2 HOP) hops) early; librosa's convention adds those hops back, so the
    # reported onset is the burst start to within the hop grid (1.5 hops = 48 ms)
    assert len(found) == 3
    assert N_FFT // (2 * HOP) == 2
    assert np.all(np.abs(found - np.array(clicks)) <= 1.5 * HOP / sr), found


def test_merge_onsets_averages_close_runs() -> None:
    from beatlite.synth.plan import merge_onsets

    out = merge_onsets([1.0, 1.1, 1.5, 2.0, 2.12, 2.24], gap=0.2)
    assert np.allclose(out, [1.05, 1.5, 2.12])  # (1.0 + 1.1) / 2; (2.0 + 2.12 + 2.24) / 3


# ----------------------------------------------------------------------------- IK and Euler
def test_two_bone_ik_reaches_reachable_targets() -> None:
    sk = beat_skeleton()
    arm, fore, hand = (sk.offsets[sk.index(n)] for n in ("RightArm", "RightForeArm", "RightHand"))
    rng = np.random.default_rng(0)
    directions = rng.normal(size=(50, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    dist = rng.uniform(22.0, 45.0, size=50)  # inside the soft limits [20.4, 45.5] cm (arm 28.5 + 25 cm)
    targets = arm + directions * dist[:, None]
    shoulder, elbow = two_bone_ik(targets, arm, fore, hand, np.array([-0.45, -1.0, -0.35]))
    # forward kinematics by hand: wrist = root + R_s (upper + R_e lower)
    wrist = arm + np.einsum("tij,tj->ti", shoulder, fore + np.einsum("tij,j->ti", elbow, hand))
    assert np.allclose(wrist, targets, atol=1e-6)
    assert np.allclose(np.linalg.det(shoulder), 1.0) and np.allclose(np.linalg.det(elbow), 1.0)
    with pytest.raises(ValueError, match=r"\(T, 3\)"):
        two_bone_ik(np.zeros(3), arm, fore, hand, np.array([0.0, -1.0, 0.0]))


def test_two_bone_ik_reaches_targets_in_line_with_the_pole() -> None:
    # a pole along the shoulder-target line leaves the elbow plane free; any plane must still give
    # rotations that reach the target. It used to give a singular "rotation" (det 0) that put the
    # wrist 42.97 cm away for a target 40 cm away.
    upper, lower, root = np.array([0.0, -30.0, 0.0]), np.array([0.0, -25.0, 0.0]), np.zeros(3)
    targets = np.array([[0.0, 0.0, 40.0], [0.0, 0.0, -30.0], [0.0, 0.0, 40.0]])
    for pole in (np.array([0.0, 0.0, -1.0]), np.array([0.0, 0.0, 2.0]), np.zeros(3)):
        shoulder, elbow = two_bone_ik(targets, root, upper, lower, pole)
        wrist = root + np.einsum("tij,tj->ti", shoulder, upper + np.einsum("tij,j->ti", elbow, lower))
        assert np.allclose(wrist, targets, atol=1e-6), pole
        assert np.allclose(np.linalg.det(shoulder), 1.0) and np.allclose(np.linalg.det(elbow), 1.0)
        assert np.allclose(np.einsum("tji,tjk->tik", shoulder, shoulder), np.eye(3), atol=1e-9)


def test_two_bone_ik_limits_elbow_flexion() -> None:
    sk = beat_skeleton()
    arm, fore, hand = (sk.offsets[sk.index(n)] for n in ("RightArm", "RightForeArm", "RightHand"))
    targets = arm + np.array([[-200.0, 0.0, 0.0], [0.0, -1.0, 0.0]])  # far away / at the shoulder
    shoulder, elbow = two_bone_ik(targets, arm, fore, hand, np.array([-0.45, -1.0, -0.35]))
    u = -hand / np.linalg.norm(hand)
    flex = np.degrees(
        np.arccos(np.clip(np.einsum("tij,j->ti", elbow, hand) @ -u / np.linalg.norm(hand), -1, 1))
    )
    assert 20.0 <= flex[0] <= 35.0  # never fully straight
    assert 135.0 <= flex[1] <= 145.0  # never beyond 145 degrees


def test_continuous_euler_crosses_the_gimbal_boundary() -> None:
    beta = np.linspace(0.0, 150.0, 61)  # an elbow flexing about its middle (Y) axis
    rot = euler_to_matrix(np.stack([0 * beta, beta, 0 * beta], axis=1), "XYZ")
    raw = matrix_to_euler(rot, "XYZ")
    assert np.abs(np.diff(raw, axis=0)).max() > 90.0  # the plain decomposition flips at 90 degrees
    fixed = continuous_euler(raw)
    assert np.abs(np.diff(fixed, axis=0)).max() < 3.0
    assert np.allclose(euler_to_matrix(fixed, "XYZ"), rot, atol=1e-9)


# ----------------------------------------------------------------------------- planning
def _words(items: list[tuple[float, float, str]], emotion: int = 0) -> list[TimedWord]:
    return [TimedWord(s, e, w, emotion) for s, e, w in items]


def test_plan_scripts_keywords_and_tiles_the_semantic_annotation() -> None:
    words = _words(
        [(1.0, 1.3, "we"), (1.4, 1.8, "bought"), (2.6, 3.0, "huge"), (3.1, 3.5, "table"), (5.5, 5.9, "small")]
    )
    plan = make_plan(words, SPEAKERS[2], 7.0, np.random.default_rng(0))
    kinds = {g.word: (g.kind, g.label) for g in plan.gestures}
    assert kinds == {"huge": ("big", "07_iconic_h"), "small": ("small", "06_iconic_m")}
    # the stroke ends at the word onset; "small" comes >= GESTURE_GAP_S (1 s) after the end of "huge":
    # hold to 3.0 s + retraction 0.6 * 1.3 = 0.78 s -> 3.78 s; preparation of "small" from 5.5 - 0.45 s
    assert all(g.onset in (2.6, 5.5) for g in plan.gestures)
    assert {b.time for b in plan.beats} <= {w.start for w in words}
    segs = semantic_segments(plan)
    assert segs[0][1] == 0.0 and segs[-1][2] == 7.0
    assert all(a[2] == b[1] for a, b in zip(segs, segs[1:]))  # contiguous
    assert all(score == SEMANTIC_SCORES[label] for label, _, _, score, _ in segs)
    assert [s[4] for s in segs if s[4]] == ["huge", "small"]


def test_emotion_table_orders_amplitude_and_speed() -> None:
    amp = {e: s.amplitude for e, s in EMOTION_STYLES.items()}
    speed = {e: s.speed for e, s in EMOTION_STYLES.items()}
    assert amp[2] > amp[5] > amp[1] > amp[0] > amp[7] > amp[4] > amp[6] > amp[3]
    assert speed[2] > speed[0] > speed[3]
    assert EMOTION_STYLES[3].head_pitch > 0 and EMOTION_STYLES[6].tremor > 0


# ----------------------------------------------------------------------------- corpus design
def test_corpus_specs_follow_beat_names_and_splits() -> None:
    specs = corpus_specs()
    assert len({s.name for s in specs}) == len(specs) == 44
    for s in specs:
        name = parse_take_name(s.name)
        assert (name.speaker_id, name.speaker, name.session_type) == (s.speaker_id, s.speaker.name, s.session)
        assert name.split == s.split and name.emotion == s.emotion
    assert {s.speaker_id for s in specs} == {2, 4, 6, 8}
    for sid in (2, 4, 6, 8):
        mine = [s for s in specs if s.speaker_id == sid]
        assert {s.split for s in mine} == {"train", "val", "test"}
        assert {0, 2, 3} <= {s.emotion for s in mine if s.session == 0}  # for the emotion ordering tests
        assert any(s.session == 1 for s in mine)
    for split in ("train", "test"):
        assert {s.emotion for s in specs if s.session == 0 and s.split == split} == set(range(8))
    counts = Counter(s.split for s in specs)
    assert counts["val"] == counts["test"] == 8


def test_speaker_styles_are_distinct() -> None:
    styles = list(SPEAKERS.values())
    assert [s.name for s in styles] == ["scott", "lawrence", "carla", "catherine"]
    for attr in ("voice", "rest", "favourite"):
        assert len({getattr(s, attr) for s in styles}) == 4, attr
    assert {s.handedness for s in styles} == {"right", "left", "both"}


def test_generate_take_rejects_bad_arguments(tmp_path: Path) -> None:
    spec = TakeSpec(2, 0, 9, 2.0)
    with pytest.raises(TypeError, match="TakeSpec"):
        generate_take("2_scott_0_9_9", tmp_path)  # type: ignore[arg-type]
    with pytest.raises(FileNotFoundError, match="does not exist"):
        generate_take(spec, tmp_path / "missing")
    with pytest.raises(ValueError, match="fps"):
        generate_take(spec, tmp_path, fps=7)


@needs_espeak
def test_generate_take_is_byte_identical_for_a_seed(tmp_path: Path) -> None:
    spec = TakeSpec(8, 0, 111, 2.5)  # a short disgust take
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    (tmp_path / "c").mkdir()
    first = generate_take(spec, tmp_path / "a", seed=3)
    second = generate_take(spec, tmp_path / "b", seed=3)
    other = generate_take(spec, tmp_path / "c", seed=4)
    assert [p.name for p in first.paths] == [p.name for p in second.paths]
    assert len(first.paths) == 6
    for p, q in zip(first.paths, second.paths):
        assert p.read_bytes() == q.read_bytes(), p.name
    assert any(p.read_bytes() != q.read_bytes() for p, q in zip(first.paths, other.paths))
    # and it reads back
    motion = read_bvh(first.paths[0])
    assert motion.fps == 30.0 and motion.duration == pytest.approx(first.duration)
    words = [iv.text for iv in read_textgrid(first.paths[3])["words"] if iv.text]
    assert words and all(w.isalpha() for w in words)
    assert read_semantic(first.paths[4])[-1].end == pytest.approx(first.duration)


@needs_espeak
def test_full_rate_take_is_the_same_motion_at_120fps(tmp_path: Path) -> None:
    (tmp_path / "full").mkdir()
    (tmp_path / "compact").mkdir()
    spec = TakeSpec(6, 0, 13, 1.5)
    result = generate_take(spec, tmp_path / "full", seed=0, full_rate=True)
    compact = generate_take(spec, tmp_path / "compact", seed=0)
    names = [p.name for p in result.paths]
    assert names[0].endswith(".bvh") and names[2].endswith(".json")
    motion = read_bvh(result.paths[0])
    assert motion.fps == 120.0 and motion.n_frames == round(result.duration * 120)
    small = read_bvh(compact.paths[0])
    assert np.abs(motion.channels[::4] - small.channels).max() <= 0.0005 + 1e-9  # 3 vs 6 decimals


def test_import_does_not_load_torch() -> None:
    code = "import sys, beatlite.synth, beatlite.synth.corpus; assert 'torch' not in sys.modules"
    run_ok([sys.executable, "-c", code])
