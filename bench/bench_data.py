"""Benchmark of beatlite.data and beatlite.stats on a BEAT-format folder (default: data_samples/).

Targets (issue 4): indexing + all statistics <= 30 s; building the window cache <= 60 s on 2 cores.
Each step is printed with a straightforward alternative measured in the same run:

- indexing from headers vs loading every take fully (``load_take``),
- per-take log-mel sliced per window vs librosa on every window separately,
- loading the window cache vs building it.

Usage: ``python bench/bench_data.py [--data FOLDER] [--out FOLDER]`` (``--out`` keeps the figures and the
window cache; without it they go to a temporary folder, deleted at the end). Timings on a shared machine
are noisy; run it twice and compare.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("BEATLITE_THREADS", "1")

import numpy as np  # noqa: E402


def _timed(label: str, fn, *args, **kwargs):
    tic = time.perf_counter()
    out = fn(*args, **kwargs)
    dt = time.perf_counter() - tic
    print(f"  {label:<52s} {dt:7.2f} s")
    return out, dt


def main() -> int:
    import matplotlib

    matplotlib.use("Agg")
    from beatlite.paths import data_dir

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=None, help="BEAT-format folder (default data_dir())")
    parser.add_argument(
        "--out",
        type=Path,
        default=None,
        help="folder for figures and caches (default: a temporary one, deleted at the end)",
    )
    args = parser.parse_args()
    root = args.data or data_dir()
    if args.out is None:  # figures and the window cache (60 MB for data_samples/) deleted at the end
        with tempfile.TemporaryDirectory(prefix="bench_data_") as tmp:
            return _run(root, Path(tmp))
    args.out.mkdir(parents=True, exist_ok=True)
    return _run(root, args.out)


def _run(root: Path, out: Path) -> int:
    import matplotlib.pyplot as plt

    from beatlite.data.index import index_folder
    from beatlite.data.windows import MEL_SETTINGS, audio_samples, audio_start, build_windows, log_mel
    from beatlite.io import load_take
    from beatlite.stats import (
        EmotionClassifier,
        emotion_separability,
        emotion_shares,
        gesture_correlations,
        language_shares,
        load_corpus,
        plot_correlations,
        plot_emotion_tsne,
        plot_figure2,
        plot_figure4,
        plot_table6,
        rotation_windows,
        score_histogram,
        speaker_durations,
        speed_by_emotion,
        table1_markdown,
        word_scores,
    )

    print(f"data: {root}\noutput: {out}")

    # ------------------------------------------------------------------ index + statistics
    print("\n[1] indexing + all statistics (target <= 30 s)")
    t_all = time.perf_counter()
    idx, t_index = _timed("index_folder (headers only)", index_folder, root)
    print(f"      {idx}")
    takes, _ = _timed("load_corpus (all usable takes at 15 fps)", load_corpus, idx)

    def statistics() -> dict:
        res = {
            "table1": table1_markdown(idx),
            "emotion_shares": emotion_shares(idx),
            "language_shares": language_shares(idx),
            "speaker_durations": speaker_durations(idx),
            "separability": emotion_separability(takes, n_permutations=200),
            "score_histogram": score_histogram(takes),
            "word_scores": word_scores(takes),
            "speed_by_emotion": speed_by_emotion(takes),
            "correlations": gesture_correlations(takes, n_permutations=1000),
        }
        train = [t for t in takes if t.split == "train"]
        test = [t for t in takes if t.split != "train"]  # val + test takes, never seen in training
        rw_train, rw_test = rotation_windows(train), rotation_windows(test)
        clf = EmotionClassifier().fit(rw_train.windows, rw_train.emotion)
        res["table6"] = clf.per_class_accuracy(rw_test.windows, rw_test.emotion)
        return res

    res, _ = _timed("statistics (tables, separability, correlations, Table 6)", statistics)

    def figures() -> None:
        plot_figure2(idx, out=out / "figure2")
        plot_emotion_tsne(takes, out=out / "figure3a")
        plot_figure4(takes, out=out / "figure4")
        plot_correlations(takes, out=out / "correlations")
        plot_table6(res["table6"], out=out / "table6")
        plt.close("all")

    _timed("figures (PNG + SVG)", figures)
    total_stats = time.perf_counter() - t_all
    print(f"  {'TOTAL index + statistics + figures':<52s} {total_stats:7.2f} s   (target 30 s)")
    print(f"      separability: {res['separability'].summary()}")
    print(
        "      speed by emotion (cm/s): "
        + ", ".join(f"{k} {v:.1f}" for k, v in res["speed_by_emotion"].items())
    )
    print(
        "      Table 6 analog (val+test windows): "
        + ", ".join(f"{k} {v:.2f}" for k, v in res["table6"].items())
    )

    records = [r for r in idx if r.usable]
    _, t_full = _timed(
        "alternative: load_take of every take (full read)",
        lambda: [load_take(r.path("motion")) for r in records],
    )
    print(f"      indexing is {t_full / t_index:.1f}x faster than reading every take")

    # ------------------------------------------------------------------ window cache
    print("\n[2] window cache (target <= 60 s)")
    cache = out / "cache"
    t0 = time.perf_counter()
    built = {}
    for split in ("train", "val", "test"):
        built[split], _ = _timed(
            f"build_windows(split={split!r}) -> cache", build_windows, idx, split=split, cache=cache
        )
    _timed(
        "build_windows(split='test', whole_takes=True)",
        build_windows,
        idx,
        split="test",
        whole_takes=True,
        cache=cache,
    )
    t_build = time.perf_counter() - t0
    print(f"  {'TOTAL cache build':<52s} {t_build:7.2f} s   (target 60 s)")
    print("      windows: " + ", ".join(f"{k} {len(v)}" for k, v in built.items()))
    t0 = time.perf_counter()
    for split in ("train", "val", "test"):
        build_windows(idx, split=split, cache=cache)
    t_load = time.perf_counter() - t0
    print(
        f"  {'loading the three cached splits':<52s} {t_load:7.2f} s   ({t_build / t_load:.0f}x faster than building)"
    )

    # ------------------------------------------------------------------ mel: per take vs per window
    print("\n[3] log-mel: one spectrogram per take, sliced, vs librosa per window")
    take = load_take(records[0].path("motion"))
    n_audio = audio_samples(34, 15, 16000)
    starts = np.arange(0, take.n_frames - 34 + 1, 10)

    def per_take() -> None:
        mel = log_mel(take.audio)
        for s in starts:
            a = audio_start(int(s), 15, 16000) // MEL_SETTINGS["hop_length"]
            _ = mel[a : a + 70]

    def per_window() -> None:
        for s in starts:
            a = audio_start(int(s), 15, 16000)
            _ = log_mel(take.audio[a : a + n_audio])

    _, t_take = _timed(f"per take ({len(starts)} windows of {records[0].stem})", per_take)
    _, t_win = _timed("per window", per_window)
    print(f"      per-take slicing is {t_win / t_take:.1f}x faster")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
