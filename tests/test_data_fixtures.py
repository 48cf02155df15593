"""Tiny hand-made BEAT-format takes for the data/stats tests (helpers + checks of the helpers).

Every file is written by the minimal writers below (formats as in docs/reference_code.md#bvh-header to #emotion-annotations),
so the tests know every value: motion channels, audio samples, words, annotations.
"""

from __future__ import annotations

import gzip
import json
from pathlib import Path

import numpy as np
import soundfile as sf

FPS_BVH = 15  # the tiny BVHs are written at 15 fps so that frame i of the file is model frame i
SR = 16000


def write_text(path: Path, text: str) -> None:
    if path.name.endswith(".gz"):
        with gzip.open(path, "wt", encoding="utf-8") as f:
            f.write(text)
    else:
        path.write_text(text, encoding="utf-8")


def write_tiny_bvh(path: Path, n_frames: int, frame_time: float = 1 / FPS_BVH) -> None:
    """A rest-pose BVH of BEAT's skeleton whose header says ``n_frames`` x ``frame_time`` (for index tests;
    BEAT's skeleton, because the index runs the skeleton code every window build runs)."""
    from beatlite.io.bvh import _header_text  # the HIERARCHY lines of beatlite's own writer
    from beatlite.skeleton.beat import beat_skeleton

    skeleton = beat_skeleton()
    lines = _header_text(skeleton) + ["MOTION", f"Frames: {n_frames}", f"Frame Time: {frame_time:.6f}"]
    lines += [" ".join(["0"] * skeleton.n_channels)] * n_frames
    write_text(path, "\n".join(lines) + "\n")


def write_beat_bvh(path: Path, channels: np.ndarray, fps: float = FPS_BVH) -> None:
    """A full 75-joint BEAT BVH (beatlite skeleton) with the given (T, 228) channels."""
    from beatlite.io import Motion, write_bvh
    from beatlite.skeleton import beat_skeleton

    write_bvh(path, Motion(beat_skeleton(), channels, fps))


def write_wav(path: Path, y: np.ndarray, sr: int = SR) -> None:
    sf.write(path, np.asarray(y, dtype=np.float32), sr, subtype="FLOAT")


def write_face_json(path: Path, weights: np.ndarray, fps: float = 60.0) -> None:
    """BEAT facial JSON: {"names": [...51], "frames": [{"time": t, "weights": [...]}, ...]}."""
    from beatlite.io import ARKIT_51  # load_take picks BEAT's 51 blendshapes by name

    names = list(ARKIT_51) if weights.shape[1] == 51 else [f"bs{k:02d}" for k in range(weights.shape[1])]
    frames = [
        {"time": round(i / fps, 6), "weights": [float(v) for v in row]} for i, row in enumerate(weights)
    ]
    write_text(path, json.dumps({"names": names, "frames": frames}))


def write_textgrid(path: Path, words: list[tuple[float, float, str]], xmax: float) -> None:
    """Long-format MFA-style TextGrid with a ``words`` tier (gaps filled with "" marks)."""
    intervals = []
    t = 0.0
    for start, end, text in words:
        if start > t:
            intervals.append((t, start, ""))
        intervals.append((start, end, text))
        t = end
    if t < xmax:
        intervals.append((t, xmax, ""))
    out = [
        'File type = "ooTextFile"',
        'Object class = "TextGrid"',
        "",
        "xmin = 0 ",
        f"xmax = {xmax:g} ",
        "tiers? <exists> ",
        "size = 1 ",
        "item []: ",
        "    item [1]:",
        '        class = "IntervalTier" ',
        '        name = "words" ',
        "        xmin = 0 ",
        f"        xmax = {xmax:g} ",
        f"        intervals: size = {len(intervals)} ",
    ]
    for k, (a, b, text) in enumerate(intervals, start=1):
        out += [
            f"        intervals [{k}]:",
            f"            xmin = {a:g} ",
            f"            xmax = {b:g} ",
            f'            text = "{text}" ',
        ]
    write_text(path, "\n".join(out) + "\n")


def write_semantic(path: Path, segments: list[tuple[str, float, float, float, str]]) -> None:
    """BEAT semantic .txt: name, start, end, duration, score, keywords (tab-separated)."""
    rows = [f"{name}\t{a:.3f}\t{b:.3f}\t{b - a:.3f}\t{score:g}\t{kw}" for name, a, b, score, kw in segments]
    write_text(path, "\n".join(rows) + "\n")


def write_emotion(path: Path, segments: list[tuple[float, float, int]], stem: str) -> None:
    """BEAT emotion .csv: name, start, end, duration, score(emotion id)."""
    rows = [f"{stem},{a:.3f},{b:.3f},{b - a:.3f},{e}" for a, b, e in segments]
    write_text(path, "\n".join(rows) + "\n")


def make_tiny_take(
    folder: Path,
    stem: str,
    seconds: float,
    *,
    modalities: tuple[str, ...] = ("bvh", "wav", "json", "TextGrid", "txt", "csv"),
    wav_seconds: float | None = None,
) -> None:
    """A take for index tests: a tiny BVH and small files of the given durations."""
    folder.mkdir(parents=True, exist_ok=True)
    if "bvh" in modalities:
        write_tiny_bvh(folder / f"{stem}.bvh", int(round(seconds * FPS_BVH)))
    if "wav" in modalities:
        n = int(round((seconds if wav_seconds is None else wav_seconds) * SR))
        write_wav(folder / f"{stem}.wav", np.zeros(n, np.float32))
    if "json" in modalities:
        write_face_json(folder / f"{stem}.json", np.zeros((int(round(seconds * 60)), 51)))
    if "TextGrid" in modalities:
        write_textgrid(folder / f"{stem}.TextGrid", [(0.5, 1.0, "hello")], xmax=seconds)
    if "txt" in modalities:
        write_semantic(folder / f"{stem}.txt", [("01_beat_align", 0.0, 1.0, 0.1, "")])
    if "csv" in modalities:
        write_emotion(folder / f"{stem}.csv", [(0.0, seconds, 0)], stem)


# ---------------------------------------------------------------------------- helper checks
def test_tiny_bvh_header_reads_back(tmp_path: Path) -> None:
    from beatlite.io import read_bvh_header

    write_tiny_bvh(tmp_path / "a.bvh", 30)
    skeleton, n, ft = read_bvh_header(tmp_path / "a.bvh")
    from beatlite.skeleton.beat import beat_skeleton

    assert skeleton.names == beat_skeleton().names and n == 30 and abs(ft - 1 / 15) < 1e-6


def test_wav_writer_round_trip(tmp_path: Path) -> None:
    y = np.linspace(-0.5, 0.5, 1600, dtype=np.float32)
    write_wav(tmp_path / "a.wav", y)
    back, sr = sf.read(tmp_path / "a.wav", dtype="float32")
    assert sr == SR and np.array_equal(back, y)
