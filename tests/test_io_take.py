"""Tests of load_take (every modality on one timeline, resampling phases, truncation) and a check that
no reader modifies its input."""

from __future__ import annotations

import os
import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from beatlite.io import (
    ARKIT_51,
    AlignmentWarning,
    EmotionSegment,
    FormatError,
    Interval,
    Motion,
    SemanticSegment,
    load_take,
    read_audio,
    read_bvh,
    read_bvh_header,
    read_emotion,
    read_facial,
    read_semantic,
    read_textgrid,
    read_words,
    write_bvh,
    write_emotion,
    write_facial,
    write_semantic,
    write_textgrid,
    write_wav,
)
from beatlite.io.take import resample_frames
from beatlite.skeleton.core import Skeleton


def skeleton() -> Skeleton:
    return Skeleton(
        names=("Hips", "Spine"),
        parents=np.array([-1, 0]),
        offsets=np.array([[0.0, 0, 0], [0, 10, 0]]),
        channels=(
            ("Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation"),
            ("Xrotation", "Yrotation", "Zrotation"),
        ),
    )


def make_take(
    folder: Path,
    stem: str = "2_scott_0_65_65",
    *,
    bvh_fps: int = 120,
    seconds: float = 2.0,
    audio_seconds: float | None = None,
    face_seconds: float | None = None,
) -> Path:
    n = int(round(bvh_fps * seconds))
    # every channel of frame k holds k (+ column offset), so decimation is visible in the values
    channels = np.arange(n, dtype=np.float64)[:, None] + np.arange(9)[None, :] * 1000
    write_bvh(folder / f"{stem}.bvh.gz", Motion(skeleton(), channels, bvh_fps))
    a_sec = seconds if audio_seconds is None else audio_seconds
    write_wav(folder / f"{stem}.wav", 0.1 * np.sin(np.arange(int(48000 * a_sec)) / 10), 48000)
    f_sec = seconds if face_seconds is None else face_seconds
    nf = int(round(60 * f_sec))
    face = np.repeat(np.arange(nf, dtype=np.float64)[:, None] / 1000, 51, axis=1)
    write_facial(folder / f"{stem}.json", ARKIT_51, face, fps=60)
    write_textgrid(
        folder / f"{stem}.TextGrid",
        {"words": [Interval(0.2, 0.6, "hello"), Interval(0.6, 1.0, "world")]},
        seconds,
    )
    write_semantic(folder / f"{stem}.txt", [SemanticSegment("01_beat_align", 0.5, 1.0, 0.5, 0.25)])
    write_emotion(folder / f"{stem}.csv", [EmotionSegment(stem, 1.0, 1.5, 0.5, 5)])
    return folder / stem


def test_load_take_start_phase(tmp_path: Path) -> None:
    stem = make_take(tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # equal lengths: no warning
        take = load_take(stem)
    assert take.name == "2_scott_0_65_65" and take.fps == 15.0 and take.n_frames == 30
    # 120 -> 15 fps: frames 0, 8, 16, ... (exact decimation from frame 0)
    np.testing.assert_array_equal(take.motion.channels[:, 0], np.arange(30) * 8)
    np.testing.assert_array_equal(take.motion.channels[:, 8], np.arange(30) * 8 + 8000)
    # face 60 -> 15 fps: frames 0, 4, 8, ...
    assert take.face is not None and take.face.shape == (30, 51)
    np.testing.assert_allclose(take.face[:, 0], np.arange(30) * 4 / 1000, rtol=1e-6)
    assert take.audio is not None and take.sr == 16000 and take.audio.shape == (32000,)
    assert take.words is not None and take.words.words == ("hello", "world")
    # semantic [0.5, 1.0] -> frames 8..15 (t = 0.533 .. 1.0); emotion [1.0, 1.5] -> frames 15..22
    assert np.flatnonzero(take.semantic).tolist() == list(range(8, 16))
    assert np.flatnonzero(take.emotion == 5).tolist() == list(range(15, 23))
    assert take.info is not None and take.info.emotion_name == "happiness"
    assert set(take.paths) == {".bvh", ".wav", ".json", ".TextGrid", ".txt", ".csv"}


def test_load_take_beat_phase_and_path_argument(tmp_path: Path) -> None:
    stem = make_take(tmp_path)
    take = load_take(str(stem) + ".bvh.gz", phase="beat")
    # BEAT keeps 120-fps frames 1, 9, 17, ... (docs/reference_code.md#downsampling): 239 source frames after frame 0 -> 30 frames
    np.testing.assert_array_equal(take.motion.channels[:, 0], 1 + np.arange(30) * 8)
    assert take.face is not None
    np.testing.assert_allclose(take.face[:, 0], np.arange(30) * 4 / 1000, rtol=1e-6)  # face from frame 0


def test_truncation_warns_with_lengths(tmp_path: Path) -> None:
    stem = make_take(tmp_path, audio_seconds=1.5)
    with pytest.warns(AlignmentWarning, match=r"motion 2\.000 s.*audio 1\.500 s.*face 2\.000 s"):
        take = load_take(stem)
    assert take.n_frames == 22  # floor(1.5 * 15)
    assert take.face is not None and take.face.shape[0] == 22
    assert take.audio is not None and take.audio.shape[0] == 23466  # floor(22 * 16000 / 15)
    assert take.semantic.shape == (22,) and take.emotion.shape == (22,)


def test_no_warning_within_one_frame(tmp_path: Path) -> None:
    stem = make_take(tmp_path, face_seconds=2.0 - 1 / 60)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        take = load_take(stem)
    assert take.n_frames == 30  # 119 face frames still give 30 frames at 15 fps (0, 4, ..., 116)


def test_missing_optional_files(tmp_path: Path) -> None:
    stem = make_take(tmp_path, stem="5_stewart_0_3_3")
    for ext in (".wav", ".json", ".TextGrid", ".txt", ".csv"):
        (tmp_path / f"5_stewart_0_3_3{ext}").unlink()
    take = load_take(stem)
    assert take.audio is None and take.face is None and take.words is None
    assert take.n_frames == 30 and (take.semantic == 0).all() and (take.emotion == 0).all()
    with pytest.raises(FileNotFoundError):
        load_take(tmp_path / "2_scott_0_9_9")


def test_non_integer_ratio_interpolates() -> None:
    # 50 -> 15 fps: output frame i is source position i * 10/3; a linear ramp stays a linear ramp
    values = np.arange(100, dtype=np.float64)[:, None] * np.array([[1.0, 2.0]])
    out = resample_frames(values, 50, 15)
    n = int(np.floor(99 * 15 / 50)) + 1  # 30 output frames inside the 99 source intervals
    np.testing.assert_allclose(out, (np.arange(n) * 10 / 3)[:, None] * np.array([[1.0, 2.0]]), atol=1e-9)


def test_angles_interpolate_the_short_way() -> None:
    # 2 -> 4 fps: source positions 0, 0.5, 1. Column 0 is an angle: 170 -> -170 is +20 deg across 180,
    # so halfway is 180 (mod 360), not 0; column 1 is a position and is interpolated linearly.
    values = np.array([[170.0, 170.0], [-170.0, -170.0]])
    out = resample_frames(values, 2.0, 4.0, angle_columns=np.array([0]))
    assert out.shape == (3, 2)
    assert out[0].tolist() == [170.0, 170.0] and out[2, 1] == -170.0
    assert abs((out[1, 0] % 360.0) - 180.0) < 1e-9
    assert out[1, 1] == 0.0
    assert abs(((out[2, 0] + 170.0) + 180.0) % 360.0 - 180.0) < 1e-9  # -170 (mod 360)


def test_finite_frames_resample_to_finite_frames_however_large() -> None:
    # 2 -> 3 fps: source positions 0, 2/3, 4/3 and 2. A position pair +-1.7e308 apart interpolates as
    # (1 - w) a + w b; an angle pair at 1.7e308 degrees (an even whole number, reduced mod 360 exactly with
    # Python integers here) interpolates along the shorter arc between the two reduced angles.
    a, b = -1.7e308, 1.7e308
    values = np.array([[a, a], [b, b], [a, a]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no overflow warnings either
        out = resample_frames(values, 2.0, 3.0, angle_columns=np.array([1]))
    w = np.array([0.0, 2 / 3, 1 / 3])
    np.testing.assert_allclose(
        out[:, 0], [a, (1 - w[1]) * a + w[1] * b, (1 - w[2]) * b + w[2] * a, a], rtol=1e-12
    )
    ra, rb = int(a) % 360, int(b) % 360
    arc = (rb - ra + 180) % 360 - 180
    want = np.array([ra, ra + w[1] * arc, rb - w[2] * arc, ra])
    assert np.all(np.abs((out[:, 1] - want + 180.0) % 360.0 - 180.0) < 1e-9)


def test_ordinary_angles_resample_to_the_same_bits_as_the_shorter_arc_formula() -> None:
    # Below ANGLE_EXACT nothing is reduced: a + w ((b - a + 180) % 360 - 180), bit for bit (the data records
    # of stores and checkpoints were made with this formula).
    rng = np.random.default_rng(0)
    values = rng.uniform(-1e4, 1e4, (40, 6)) * rng.choice([1e-3, 1.0, 1e8], (40, 6))
    out = resample_frames(values, 1.0, 4.0, angle_columns=np.array([0, 2, 4]))
    pos = np.arange(len(out)) / 4  # 0, 1/4, 1/2, ...: exact in binary
    i0 = np.floor(pos + 1e-9).astype(int)
    w = (pos - i0)[:, None]
    a, b = values[i0], values[np.minimum(i0 + 1, 39)]
    delta = b - a
    delta[:, [0, 2, 4]] = (delta[:, [0, 2, 4]] + 180.0) % 360.0 - 180.0
    np.testing.assert_array_equal(out, a + w * delta)


def test_random_finite_frames_of_any_size_resample_to_finite_frames() -> None:
    rng = np.random.default_rng(1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for _ in range(200):
            t, d = rng.integers(2, 9), rng.integers(1, 5)
            exponent = np.where(
                rng.random((t, d)) < 0.5, rng.uniform(307.5, 308.25, (t, d)), rng.uniform(-5, 5, (t, d))
            )
            values = rng.choice([-1, 1], (t, d)) * 10.0**exponent  # half near float64's largest
            cols = np.flatnonzero(rng.random(d) < 0.5)
            out = resample_frames(
                values, float(rng.uniform(1, 100)), float(rng.uniform(1, 100)), angle_columns=cols
            )
            assert np.isfinite(out).all()


# ----------------------------------------------------------------------------- readers never write


def _snapshot(folder: Path) -> dict[str, tuple[bytes, int, int]]:
    return {
        p.name: (p.read_bytes(), p.stat().st_mtime_ns, p.stat().st_mode) for p in sorted(folder.iterdir())
    }


def test_readers_do_not_modify_generated_files(tmp_path: Path) -> None:
    stem = make_take(tmp_path)
    before = _snapshot(tmp_path)
    name = stem.name
    readers: list[tuple[Callable[..., object], str]] = [
        (read_bvh, ".bvh.gz"),
        (read_bvh_header, ".bvh.gz"),
        (read_audio, ".wav"),
        (read_facial, ".json"),
        (read_textgrid, ".TextGrid"),
        (read_words, ".TextGrid"),
        (read_semantic, ".txt"),
        (read_emotion, ".csv"),
    ]
    for reader, ext in readers:
        reader(tmp_path / f"{name}{ext}")
    load_take(stem)
    assert _snapshot(tmp_path) == before  # same files, bytes, mtimes and permissions; no temp files


def test_failing_readers_do_not_modify(tmp_path: Path) -> None:
    bad = tmp_path / "bad.bvh"
    bad.write_text("HIERARCHY\nROOT a\n{\n")
    for ext in (".wav", ".json", ".TextGrid", ".txt", ".csv"):
        (tmp_path / f"bad{ext}").write_text("version https://git-lfs.github.com/spec/v1\n")
    before = _snapshot(tmp_path)
    for reader, ext in [
        (read_bvh, ".bvh"),
        (read_audio, ".wav"),
        (read_facial, ".json"),
        (read_textgrid, ".TextGrid"),
        (read_semantic, ".txt"),
        (read_emotion, ".csv"),
    ]:
        with pytest.raises(FormatError):
            reader(tmp_path / f"bad{ext}")
    assert _snapshot(tmp_path) == before


def test_real_files_untouched(real_samples: Path) -> None:
    before = {p.name: (p.read_bytes(), os.stat(p).st_mtime_ns) for p in real_samples.iterdir()}
    read_bvh(real_samples / "beat_skeleton_2_scott_0_1_1_frame0.bvh")
    read_bvh(real_samples / "dataset-1_bye_normal_001.bvh")
    read_audio(real_samples / "2_scott_0_2_2.wav")
    read_textgrid(real_samples / "2_scott_0_2_2.TextGrid")
    after = {p.name: (p.read_bytes(), os.stat(p).st_mtime_ns) for p in real_samples.iterdir()}
    assert after == before


def test_clip_take_cuts_every_modality_onto_one_timeline(tmp_path: Path) -> None:
    from beatlite.io.take import clip_take

    take = load_take(make_take(tmp_path), fps=15)  # 2 s: 30 frames, frame k of the bvh is 8k at 120 fps
    clip = clip_take(take, 0.4, 1.2)  # frames round(6.0) = 6 to round(18.0) = 18
    assert clip.n_frames == 12 and clip.fps == 15
    np.testing.assert_array_equal(clip.motion.channels, take.motion.channels[6:18])
    np.testing.assert_array_equal(clip.face, take.face[6:18])
    np.testing.assert_array_equal(clip.emotion, take.emotion[6:18])
    np.testing.assert_array_equal(clip.semantic, take.semantic[6:18])
    # audio: samples 0.4 * sr to 1.2 * sr
    a, b = int(round(0.4 * take.sr)), int(round(1.2 * take.sr))
    np.testing.assert_array_equal(clip.audio, take.audio[a:b])
    # words "hello" [0.2, 0.6) and "world" [0.6, 1.0): shifted by 0.4 s, hello cut at 0
    assert clip.words.words == ("hello", "world")
    np.testing.assert_allclose(clip.words.starts, [0.0, 0.2], atol=1e-12)
    np.testing.assert_allclose(clip.words.ends, [0.2, 0.6], atol=1e-12)
    # semantic segment [0.5, 1.0] -> [0.1, 0.6]; emotion [1.0, 1.5] -> [0.6, 0.8] (cut at the clip's end)
    (sem,) = clip.semantic_segments
    assert (sem.start, sem.end, sem.score) == pytest.approx((0.1, 0.6, 0.25))
    (emo,) = clip.emotion_segments
    assert (emo.start, emo.end, emo.duration, emo.emotion) == pytest.approx((0.6, 0.8, 0.2, 5))
    assert take.n_frames == 30  # the source is untouched


def test_clip_take_past_the_end_and_bad_intervals(tmp_path: Path) -> None:
    from beatlite.io.take import clip_take

    take = load_take(make_take(tmp_path), fps=15)
    tail = clip_take(take, 1.8, 5.0)  # cut to the end: frames 27..29
    assert tail.n_frames == 3 and tail.words.words == ()
    for t0, t1 in ((1.0, 1.0), (-0.1, 1.0), (2.5, 3.0)):
        with pytest.raises(ValueError, match="clip_take"):
            clip_take(take, t0, t1)
