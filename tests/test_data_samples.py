"""The committed ``data_samples/`` corpus: formats, consistency and the planted effects.

Every effect test compares against a control that the same statistic would not separate on
unstructured data (time-shifted pairs, other emotions, other speakers, other gesture types).
"""

from __future__ import annotations

from collections import Counter, defaultdict
from pathlib import Path

import numpy as np
import pytest
import soundfile as sf

from beatlite.io import (
    ARKIT_51,
    parse_take_name,
    read_audio,
    read_bvh,
    read_bvh_header,
    read_emotion,
    read_facial,
    read_semantic,
    read_textgrid,
)

FPS_TOLERANCE_S = 1 / 30  # one BVH frame of the compact corpus


def _stems(folder: Path) -> list[str]:
    return sorted(p.name[: -len(".wav")] for p in folder.glob("*.wav"))


@pytest.fixture(scope="module")
def takes(data_samples: Path) -> dict[str, dict]:
    """Every take: motion, world positions, audio, face, words, semantic and emotion segments."""
    out = {}
    for stem in _stems(data_samples):
        base = data_samples / stem
        motion = read_bvh(f"{base}.bvh.gz")
        y, sr = read_audio(f"{base}.wav")
        out[stem] = {
            "name": parse_take_name(stem),
            "motion": motion,
            "pos": motion.positions(),
            "audio": y,
            "sr": sr,
            "face": read_facial(f"{base}.json.gz"),
            "tiers": read_textgrid(f"{base}.TextGrid"),
            "semantic": read_semantic(f"{base}.txt"),
            "emotion": read_emotion(f"{base}.csv"),
        }
    return out


def _joint(take: dict, name: str) -> np.ndarray:
    return take["pos"][:, take["motion"].skeleton.index(name)]


def _wrist_speed(take: dict, hand: str) -> np.ndarray:
    """(T,) cm/s, central differences."""
    p = _joint(take, hand)
    return np.linalg.norm(np.gradient(p, axis=0), axis=1) * take["motion"].fps


# ----------------------------------------------------------------------------- formats
def test_every_take_has_six_files(data_samples: Path) -> None:
    stems = _stems(data_samples)
    assert len(stems) >= 40
    for stem in stems:
        for ext in (".bvh.gz", ".wav", ".json.gz", ".TextGrid", ".txt", ".csv"):
            assert (data_samples / f"{stem}{ext}").is_file(), f"{stem}{ext} missing"


def test_modalities_agree_in_duration(takes: dict[str, dict]) -> None:
    for stem, tk in takes.items():
        durations = {
            "bvh": tk["motion"].duration,
            "wav": tk["audio"].size / tk["sr"],
            "face": tk["face"].n_frames / 60.0,
            "textgrid": max(iv.end for iv in tk["tiers"]["words"]),
            "semantic": tk["semantic"][-1].end,
            "emotion": tk["emotion"][-1].end,
        }
        spread = max(durations.values()) - min(durations.values())
        assert spread <= FPS_TOLERANCE_S + 1e-9, (stem, durations)


def test_audio_is_16k_mono_pcm16(data_samples: Path) -> None:
    for stem in _stems(data_samples):
        info = sf.info(str(data_samples / f"{stem}.wav"))
        assert (info.samplerate, info.channels, info.subtype) == (16000, 1, "PCM_16"), stem


def test_skeleton_equals_real_beat_header(data_samples: Path, real_samples: Path) -> None:
    real, _, _ = read_bvh_header(real_samples / "beat_skeleton_2_scott_0_1_1_frame0.bvh")
    for stem in _stems(data_samples)[:3]:
        ours, _, fps = read_bvh_header(data_samples / f"{stem}.bvh.gz")
        assert ours.names == real.names
        assert np.array_equal(ours.parents, real.parents)
        assert ours.channels == real.channels
        assert sorted(ours.end_sites) == sorted(real.end_sites)
        assert 1.0 / fps == pytest.approx(30.0, rel=1e-4)  # read_bvh_header gives the frame time


def test_textgrid_tiers_as_mfa_writes_them(takes: dict[str, dict]) -> None:
    for stem, tk in takes.items():
        tiers = tk["tiers"]
        assert list(tiers) == ["words", "phones"], stem
        for name, ivs in tiers.items():
            starts = np.array([iv.start for iv in ivs])
            ends = np.array([iv.end for iv in ivs])
            assert starts[0] == 0.0 and np.allclose(starts[1:], ends[:-1]), (stem, name)  # tiles
            assert ivs[0].text == "" and ivs[-1].text == "", (stem, name)  # silence at both ends
        words = [iv.text for iv in tiers["words"] if iv.text]
        assert all(w == w.lower() and w.isalpha() for w in words), stem
        # every phone lies inside a word
        word_spans = [(iv.start, iv.end) for iv in tiers["words"] if iv.text]
        for iv in tiers["phones"]:
            if iv.text:
                assert any(s - 1e-6 <= iv.start and iv.end <= e + 1e-6 for s, e in word_spans), (stem, iv)


def test_face_is_51_arkit_at_60fps_with_blinks(takes: dict[str, dict]) -> None:
    for stem, tk in takes.items():
        face = tk["face"]
        assert face.names == ARKIT_51 and face.weights.shape[1] == 51
        assert face.fps == pytest.approx(60.0)
        assert face.weights.min() >= 0.0 and face.weights.max() <= 1.0
        blink = face.weights[:, ARKIT_51.index("eyeBlinkLeft")]
        closed = np.flatnonzero(blink > 0.8) / 60.0
        assert closed.size > 0, stem
        gaps = np.diff(
            np.concatenate([[0.0], closed[np.diff(closed, prepend=-1.0) > 0.5], [face.n_frames / 60]])
        )
        assert gaps.max() < 6.5, (stem, gaps.max())  # a blink every 3-5 s (first within 3 s)


def test_jaw_follows_the_audio_envelope(takes: dict[str, dict]) -> None:
    for stem, tk in list(takes.items())[:8]:
        y, sr = tk["audio"], tk["sr"]
        n = tk["face"].n_frames
        hop = sr // 60
        rms = np.sqrt(np.mean(y[: n * hop].reshape(n, hop) ** 2, axis=1))
        jaw = tk["face"].weights[:, ARKIT_51.index("jawOpen")]
        assert np.corrcoef(rms, jaw)[0, 1] > 0.5, stem


# ----------------------------------------------------------------------------- corpus design
def test_corpus_content_and_splits(takes: dict[str, dict], data_samples: Path) -> None:
    names = [tk["name"] for tk in takes.values()]
    assert {n.speaker_id for n in names} == {2, 4, 6, 8}
    assert {n.session_type for n in names} == {0, 1}
    total = sum(tk["motion"].duration for tk in takes.values())
    assert 600.0 <= total <= 780.0, total
    by_split = Counter()
    for tk in takes.values():
        by_split[tk["name"].split] += tk["motion"].duration
    for split, share in (("train", 0.70), ("val", 0.15), ("test", 0.15)):
        assert abs(by_split[split] / total - share) < 0.06, (split, by_split[split] / total)
    for sid in (2, 4, 6, 8):
        assert {n.split for n in names if n.speaker_id == sid} == {"train", "val", "test"}, sid
    speech = [n for n in names if n.session_type == 0]
    for split in ("train", "test"):
        assert {n.emotion for n in speech if n.split == split} == set(range(8)), split
    size = sum(p.stat().st_size for p in data_samples.iterdir() if p.is_file())
    assert size <= 40_000_000, size  # hard limit 40 MB


def test_emotion_annotations(takes: dict[str, dict]) -> None:
    for stem, tk in takes.items():
        segs = tk["emotion"]
        assert segs[0].start == 0.0
        assert all(np.isclose(a.end, b.start) for a, b in zip(segs, segs[1:])), stem
        if tk["name"].session_type == 0:
            assert [s.emotion for s in segs] == [tk["name"].emotion], stem
        else:  # the conversation changes emotion turn by turn
            assert len({s.emotion for s in segs}) >= 3, stem


def test_semantic_annotations(takes: dict[str, dict]) -> None:
    expected = {"00_nogesture": 0.0, "01_beat_align": 0.1}
    labels = Counter()
    for stem, tk in takes.items():
        segs = tk["semantic"]
        assert segs[0].start == 0.0 and all(np.isclose(a.end, b.start) for a, b in zip(segs, segs[1:])), stem
        for s in segs:
            labels[s.type] += 1
            if s.type in expected:
                assert s.score == expected[s.type]
            else:  # deictic 0.3-0.5 < iconic 0.5-0.7 < metaphoric 0.8-1.0, with the keyword
                lo, hi = {"deictic": (0.3, 0.5), "iconic": (0.5, 0.7), "metaphoric": (0.8, 1.0)}[s.type[3:-2]]
                assert lo <= s.score <= hi and s.keywords, (stem, s)
    for kind in ("deictic", "iconic", "metaphoric"):
        assert sum(v for k, v in labels.items() if kind in k) >= 20, labels


# ----------------------------------------------------------------------------- motion sanity
def test_motion_is_smooth_and_within_limits(takes: dict[str, dict]) -> None:
    for stem, tk in takes.items():
        m = tk["motion"]
        sk = m.skeleton
        step = np.abs(np.diff(m.channels, axis=0)).max()
        assert step < 30.0, (stem, step)  # < 900 deg/s at 30 fps: no jumps or Euler flips
        for hand in ("RightHand", "LeftHand"):
            assert _wrist_speed(tk, hand).max() < 350.0, (stem, hand)  # cm/s
        for side in ("Right", "Left"):
            upper = _joint(tk, f"{side}ForeArm") - _joint(tk, f"{side}Arm")
            lower = _joint(tk, f"{side}Hand") - _joint(tk, f"{side}ForeArm")
            cos = np.sum(upper * lower, 1) / np.linalg.norm(upper, axis=1) / np.linalg.norm(lower, axis=1)
            flex = np.degrees(np.arccos(np.clip(cos, -1, 1)))
            assert flex.min() >= 0.0 and flex.max() <= 150.0, (stem, side, flex.max())
            for j, name in enumerate(sk.names):
                if name.startswith(f"{side}Hand") and name != f"{side}Hand":
                    ang = m.channels[:, sk.rotation_channel_indices(j)]
                    assert np.abs(ang).max() <= 100.0, (stem, name)
        for name in ("Neck", "Neck1", "Head", "Spine", "Spine1", "Spine2", "Spine3"):
            ang = m.channels[:, sk.rotation_channel_indices(sk.index(name))]
            assert np.abs(ang).max() <= 30.0, (stem, name)
        legs = [j for j, n in enumerate(sk.names) if any(k in n for k in ("Leg", "Foot", "Toe"))]
        feet = tk["pos"][:, [sk.index("RightToeBase"), sk.index("LeftToeBase")]]
        assert np.ptp(feet, axis=0).max() < 10.0, stem  # legs near-static (feet move < 10 cm)
        assert legs


# ----------------------------------------------------------------------------- planted effects
def _stroke_ends(speed: np.ndarray, fps: float) -> np.ndarray:
    """Motion beats: local speed minima preceded within 0.3 s by a peak >= 15 cm/s at least 5x higher."""
    from scipy.signal import argrelmin

    window = int(round(0.3 * fps))
    keep = []
    for i in argrelmin(speed, order=1)[0]:
        if i >= window:
            peak = speed[i - window : i].max()
            if peak >= 15.0 and speed[i] <= 0.2 * peak:
                keep.append(i)
    return np.array(keep, dtype=np.float64) / fps


def _alignment(motion_beats: np.ndarray, onsets: np.ndarray, sigma: float = 0.05) -> float:
    """Mean over motion beats of exp(-d^2 / 2 sigma^2), d = distance to the nearest audio onset (s)."""
    d = np.abs(motion_beats[:, None] - onsets[None, :]).min(axis=1)
    return float(np.mean(np.exp(-(d**2) / (2 * sigma**2))))


@pytest.mark.slow  # librosa's first onset detection JIT-compiles (~8 s); then ~0.1 s per take
def test_motion_beats_align_with_audio_onsets(takes: dict[str, dict]) -> None:
    import librosa

    shifts = (-0.5, -0.4, -0.3, -0.2, 0.2, 0.3, 0.4, 0.5)
    wins, gains = [], []
    for tk in takes.values():
        if tk["name"].session_type != 0:
            continue
        onsets = librosa.onset.onset_detect(y=tk["audio"], sr=tk["sr"], units="time", hop_length=256)
        for hand in ("RightHand", "LeftHand"):
            beats = _stroke_ends(_wrist_speed(tk, hand), tk["motion"].fps)
            if beats.size < 5:
                continue
            aligned = _alignment(beats, onsets)
            shifted = np.mean([_alignment(beats, onsets + s) for s in shifts])
            wins.append(aligned > shifted)
            gains.append(aligned - shifted)
    assert len(gains) >= 40
    assert np.mean(wins) >= 0.8, np.mean(wins)
    assert np.mean(gains) >= 0.08, np.mean(gains)


def _chest_frame_wrists(tk: dict) -> np.ndarray:
    """(T, 2, 3) wrist positions relative to Spine3 (cm)."""
    spine3 = _joint(tk, "Spine3")
    return np.stack([_joint(tk, "RightHand") - spine3, _joint(tk, "LeftHand") - spine3], axis=1)


def test_speed_and_amplitude_order_by_emotion(takes: dict[str, dict]) -> None:
    speed: dict[int, dict[int, list[float]]] = defaultdict(lambda: defaultdict(list))
    amplitude: dict[int, dict[int, list[float]]] = defaultdict(lambda: defaultdict(list))
    for tk in takes.values():
        n = tk["name"]
        if n.session_type != 0:
            continue
        v = (_wrist_speed(tk, "RightHand") + _wrist_speed(tk, "LeftHand")) / 2
        speed[n.speaker_id][n.emotion].append(float(v.mean()))
        w = _chest_frame_wrists(tk)  # amplitude: mean distance of the wrists from the rest pose (frame 0)
        amplitude[n.speaker_id][n.emotion].append(float(np.linalg.norm(w - w[:1], axis=-1).mean()))
    for sid in (2, 4, 6, 8):
        s = {e: np.mean(v) for e, v in speed[sid].items()}
        a = {e: np.mean(v) for e, v in amplitude[sid].items()}
        assert s[2] > s[0] > s[3], (sid, s)  # anger > neutral > sadness
        assert a[2] > a[0] > a[3], (sid, a)


def _window_features(tk: dict, seconds: float = 2.0) -> np.ndarray:
    """Per 2-s window: mean and std of both wrists (chest frame), mean wrist speeds, mean hand gap."""
    w = _chest_frame_wrists(tk)
    v = np.stack([_wrist_speed(tk, "RightHand"), _wrist_speed(tk, "LeftHand")], axis=1)
    gap = np.linalg.norm(w[:, 0] - w[:, 1], axis=1)
    size = int(seconds * tk["motion"].fps)
    rows = []
    for s in range(0, w.shape[0] - size + 1, size):
        sl = slice(s, s + size)
        rows.append(
            np.concatenate([w[sl].mean(0).ravel(), w[sl].std(0).ravel(), v[sl].mean(0), [gap[sl].mean()]])
        )
    return np.array(rows)


def test_speaker_is_identifiable_from_motion_statistics(takes: dict[str, dict]) -> None:
    from sklearn.linear_model import LogisticRegression
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    data = {"train": ([], []), "heldout": ([], [])}
    for tk in takes.values():
        part = "train" if tk["name"].split == "train" else "heldout"
        x = _window_features(tk)
        data[part][0].append(x)
        data[part][1].append(np.full(len(x), tk["name"].speaker_id))
    xtr, ytr = np.concatenate(data["train"][0]), np.concatenate(data["train"][1])
    xte, yte = np.concatenate(data["heldout"][0]), np.concatenate(data["heldout"][1])
    clf = make_pipeline(StandardScaler(), LogisticRegression(max_iter=2000)).fit(xtr, ytr)
    accuracy = float((clf.predict(xte) == yte).mean())
    assert accuracy >= 0.8, accuracy  # chance is 0.25 (4 speakers)


def test_big_gestures_spread_the_hands_more_than_small_ones(takes: dict[str, dict]) -> None:
    gaps: dict[str, list[np.ndarray]] = {"big": [], "small": []}
    for tk in takes.values():
        w = _chest_frame_wrists(tk)
        gap = np.linalg.norm(w[:, 0] - w[:, 1], axis=1)
        t = np.arange(gap.size) / tk["motion"].fps
        for s in tk["semantic"]:
            kind = (
                "big"
                if s.keywords in ("big", "huge", "large")
                else "small"
                if s.keywords in ("small", "little", "tiny")
                else None
            )
            if kind:
                gaps[kind].append(gap[(t >= s.start) & (t <= s.end)])
    big, small = np.concatenate(gaps["big"]), np.concatenate(gaps["small"])
    assert len(gaps["big"]) >= 5 and len(gaps["small"]) >= 5
    assert big.mean() > small.mean() + 30.0, (big.mean(), small.mean())
