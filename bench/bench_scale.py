"""Scale benchmark of the window store (issue 17): build time, peak memory, disk and loader speed vs corpus hours.

For each N (hours) it builds a BEAT-rate corpus from ``data_samples/`` in a temporary folder with
beatlite's own readers and writers -- every speaker's takes joined (cycled) to 1-min speech and
10-min conversation takes, 120 fps plain BVH (6 decimals), 48 kHz stereo 16-bit WAV, 60 fps JSON,
TextGrid / semantic / emotion annotations shifted along, BEAT's ``{speaker_id}/`` layout, valid
stems with every split populated (speech: neutral sequences 9.. train, 1.. test, 57.. val, and the
emotional blocks 65-118 alternately; conversation 2.. train, 1 test, 12 val) -- then measures, each step in a fresh subprocess so that its peak RSS is its own:

- ``store``: ``index_folder`` (timed apart), then :func:`beatlite.data.store.build_store` (``--workers``
  spawned processes) and a second, no-op ``build_store``: seconds, CPU seconds, peak RSS of the main
  process and of the largest worker, store size on disk;
- ``epoch``: one shuffled pass over the train windows with :func:`beatlite.data.torch_dataset.window_loader`
  (batch 32, CaMN's keys, ``--loader-workers`` workers): windows/s and peak RSS (main, largest worker);
- ``stats`` (``--stats``): :func:`beatlite.stats.emotion_separability` over :func:`beatlite.stats.iter_corpus`
  (at most 2000 windows scored): seconds and peak RSS; ``--step stats CORPUS all`` scores every window (the
  O(N^2) alternative);
- ``build_windows`` (the alternative, for N <= ``--compare-max-hours``): the train windows held in memory by
  :func:`beatlite.data.windows.build_windows` (a store in its cache folder, built serially, then every window read into RAM):
  seconds, peak RSS, its store's size.

Targets (issue 17): peak RSS of build and epoch <= 2 GiB at every size, store <= 0.5 GB per hour of
mocap, build <= 30 s per hour on 2 cores, loader >= 5 x CaMN tiny's CPU training rate (151 windows/s).
Growth exponents are least-squares slopes of log(value) against log(hours) (1 = linear, 0 = flat).
CPU seconds (the step's process plus its finished workers) are printed beside wall time: on a shared
machine ``CPU s / 2`` is what 2 free cores would take.

Usage: ``python bench/bench_scale.py [--hours 0.25 1] [--workers 2] [--keep DIR] [--json FILE]``. Needs about
1.8 GB of temporary disk per corpus hour (plain BVH + WAV) plus the store; timings on a shared
machine are noisy.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("BEATLITE_THREADS", "1")

import numpy as np  # noqa: E402

from beatlite.io.atomic import write_json  # noqa: E402
from beatlite.paths import n_threads, record_about  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
SPEECH_S, CONVERSATION_S = 60.0, 600.0
#: Keys CaMN reads (beatlite/models/camn.py).
CAMN_KEYS = ("pose", "audio", "face", "word", "emotion", "semantic", "speaker")
CAMN_TINY_WINDOWS_PER_S = 151.0  # issue 17: CaMN tiny training, 1 thread, batch 32


# ---------------------------------------------------------------------- corpus
def _sequences(conversation: bool) -> list[int]:
    """Sequence ids in an order that fills train, test and val early (4-hour speakers' splits).

    Speech: a neutral train, test and val sequence first, then emotional (65-118, one block per
    emotion, inner = train sequences first) and further neutral ones alternately, so every corpus
    from 0.25 h on has several emotions, as BEAT (64 neutral and 54 emotional sequences).
    """
    if conversation:
        return [2, 1, 12, *range(3, 12)]
    train, test, val = list(range(9, 57)), list(range(1, 9)), list(range(57, 65))
    neutral = [train.pop(0), test.pop(0), val.pop(0)]
    while train or test or val:
        neutral += [train.pop(0) for _ in range(min(8, len(train)))]
        neutral += [x.pop(0) for x in (test, val) if x]
    blocks = [(65, 72), (73, 80), (81, 86), (87, 94), (95, 102), (103, 110), (111, 118)]
    inner = [first + k for k in range(1, 7) for first, last in blocks if first + k < last]
    emotional = inner + [first for first, _ in blocks] + [last for _, last in blocks]
    order = neutral[:3]
    for k in range(max(len(neutral) - 3, len(emotional))):
        order += [x[k] for x in (emotional, neutral[3:]) if k < len(x)]
    return order


def corpus_plan(hours: float, speakers: list[tuple[int, str]]) -> list[tuple[int, str, int, int, float]]:
    """(speaker_id, name, session, sequence, seconds) of the takes of an ``hours`` corpus.

    Each speaker gets ``hours / len(speakers)``: conversation (10 min) for about half, speech (1 min) the rest.
    """
    per_speaker = hours * 3600.0 / len(speakers)
    n_conv = int(round(per_speaker / 2 / CONVERSATION_S))
    n_speech = max(1, int(round((per_speaker - n_conv * CONVERSATION_S) / SPEECH_S)))
    if n_speech > 118 or n_conv > 12:
        raise ValueError(f"corpus_plan: {hours} h needs more sequences per speaker than BEAT's splits list")
    plan = []
    for sid, name in speakers:
        plan += [(sid, name, 1, s, CONVERSATION_S) for s in _sequences(True)[:n_conv]]
        plan += [(sid, name, 0, s, SPEECH_S) for s in _sequences(False)[:n_speech]]
    return plan


def _load_source(record) -> dict:
    """One data_samples take at its stored rates, cut to a common duration (multiple of 0.1 s)."""
    from beatlite.io import read_audio, read_bvh, read_emotion, read_facial, read_semantic, read_words

    motion = read_bvh(record.path("motion"))
    audio, _ = read_audio(record.path("audio"), sr=16000)
    face = read_facial(record.path("face"))
    seconds = np.floor(min(motion.duration, len(audio) / 16000, len(face.weights) / face.fps) * 10) / 10
    return {
        "motion": motion,
        "audio": audio[: int(round(seconds * 16000))],
        "face": face,
        "words": read_words(record.path("text")),
        "semantic": read_semantic(record.path("semantic")),
        "emotion": read_emotion(record.path("emotion")),
        "seconds": float(seconds),
    }


def _upsample(channels: np.ndarray, factor: int) -> np.ndarray:
    """Linear interpolation of (T, C) rows to T * factor rows."""
    t = np.arange(len(channels) * factor) / factor
    i0 = np.minimum(np.floor(t).astype(np.int64), len(channels) - 1)
    i1 = np.minimum(i0 + 1, len(channels) - 1)
    frac = (t - i0)[:, None]
    return channels[i0] * (1 - frac) + channels[i1] * frac


def write_joined_take(folder: Path, stem: str, sources: list[dict], seconds: float) -> None:
    """Join ``sources`` (cycled) to ``seconds`` and write the take at BEAT rates with beatlite's writers."""
    from scipy.signal import resample_poly

    from beatlite.io import (
        Motion,
        write_bvh,
        write_emotion,
        write_facial,
        write_semantic,
        write_textgrid,
        write_wav,
    )
    from beatlite.io.emotion import EmotionSegment
    from beatlite.io.semantic import SemanticSegment
    from beatlite.io.textgrid import Interval

    parts, t0, k = [], 0.0, 0
    while t0 < seconds:
        parts.append((t0, sources[k % len(sources)]))
        t0 += sources[k % len(sources)]["seconds"]
        k += 1
    src_fps = parts[0][1]["motion"].fps
    channels = np.concatenate([s["motion"].channels[: int(round(s["seconds"] * src_fps))] for _, s in parts])
    channels = _upsample(channels[: int(round(seconds * src_fps))], int(round(120 / src_fps)))
    write_bvh(folder / f"{stem}.bvh", Motion(parts[0][1]["motion"].skeleton, channels, 120.0))
    audio = np.concatenate([s["audio"] for _, s in parts])[: int(round(seconds * 16000))]
    audio48 = np.clip(resample_poly(audio, 3, 1), -1.0, 1.0)
    write_wav(folder / f"{stem}.wav", np.stack([audio48, audio48], axis=1), 48000)
    weights = np.concatenate([s["face"].weights[: int(round(s["seconds"] * 60))] for _, s in parts])
    write_facial(
        folder / f"{stem}.json", parts[0][1]["face"].names, weights[: int(round(seconds * 60))], fps=60
    )
    words, sem, emo = [], [], []
    for t, s in parts:
        w = s["words"]
        words += [Interval(t + a, t + b, m) for a, b, m in zip(w.starts, w.ends, w.words) if t + b <= seconds]
        sem += [
            SemanticSegment(g.type, t + g.start, t + g.end, g.duration, g.score, g.keywords)
            for g in s["semantic"]
        ]
        emo += [
            EmotionSegment(g.name, t + g.start, min(t + g.end, seconds), 0.0, g.emotion) for g in s["emotion"]
        ]
    sem = [g for g in sem if g.end <= seconds]
    emo = [g._replace(duration=g.end - g.start) for g in emo if g.start < seconds]
    write_textgrid(folder / f"{stem}.TextGrid", {"words": words}, seconds)
    write_semantic(folder / f"{stem}.txt", sem)
    write_emotion(folder / f"{stem}.csv", emo)


def _make_one(job: tuple[str, str, str, list[str], float]) -> str:
    data, out, stem, source_stems, seconds = job
    from beatlite.data.index import index_folder

    idx = index_folder(data, read_durations=False)
    sources = [_load_source(idx[s]) for s in source_stems]
    folder = Path(out) / stem.split("_")[0]
    folder.mkdir(parents=True, exist_ok=True)
    write_joined_take(folder, stem, sources, seconds)
    return stem


def make_corpus(data: Path, out: Path, hours: float, workers: int) -> int:
    """Write the ``hours`` corpus under ``out`` (in ``workers`` processes); returns the number of takes."""
    from concurrent.futures import ProcessPoolExecutor
    from multiprocessing import get_context

    from beatlite.data.index import index_folder

    idx = index_folder(data, read_durations=False)
    speakers = sorted({(r.speaker_id, r.speaker) for r in idx if r.usable})
    jobs = []
    for sid, name, session, seq, seconds in corpus_plan(hours, speakers):
        own = [r.stem for r in idx if r.speaker_id == sid and r.usable]
        rotate = seq % len(own)  # different takes start different joins
        jobs.append(
            (str(data), str(out), f"{sid}_{name}_{session}_{seq}_{seq}", own[rotate:] + own[:rotate], seconds)
        )
    with ProcessPoolExecutor(workers, mp_context=get_context("spawn")) as pool:
        return len(list(pool.map(_make_one, jobs)))


# ---------------------------------------------------------------------- measured steps (subprocesses)
def _peak_rss() -> dict[str, float]:
    """Peak RSS in GiB of this process and of its largest finished child (ru_maxrss is KiB on Linux)."""
    return {
        "rss_main_gib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20,
        "rss_child_gib": resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 2**20,
    }


def _cpu_seconds() -> float:
    """User + system CPU seconds of this process and its finished children (workers)."""
    usage = [resource.getrusage(who) for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)]
    return sum(u.ru_utime + u.ru_stime for u in usage)


def step_store(corpus: Path, store: Path, workers: int) -> dict:
    from beatlite.data.index import index_folder
    from beatlite.data.store import build_store

    tic = time.perf_counter()
    index = index_folder(corpus)
    index_s = time.perf_counter() - tic
    tic, cpu = time.perf_counter(), _cpu_seconds()
    built = build_store(index, store, workers=workers)
    seconds, cpu = time.perf_counter() - tic, _cpu_seconds() - cpu
    tic = time.perf_counter()
    build_store(index, store, workers=workers)
    return {
        "index_s": index_s,
        "seconds": seconds,
        "cpu_s": cpu,
        "noop_rebuild_s": time.perf_counter() - tic,
        "disk_gb": built.disk_bytes() / 1e9,
        "mocap_hours": built.n_frames() / built.params["fps"] / 3600,
        "train_windows": len(built.windows("train", keys=("start",))),
        **_peak_rss(),
    }


def step_epoch(store: Path, workers: int, keys: tuple[str, ...]) -> dict:
    import torch

    from beatlite.data.store import WindowStore
    from beatlite.data.torch_dataset import window_loader

    torch.set_num_threads(1)
    windows = WindowStore.open(store).windows("train", keys=keys)
    tic, cpu = time.perf_counter(), _cpu_seconds()
    n = 0
    for batch in window_loader(windows, batch_size=32, shuffle=True, num_workers=workers, seed=0):
        n += len(batch["speaker"]) if "speaker" in batch else len(next(iter(batch.values())))
    seconds, cpu = time.perf_counter() - tic, _cpu_seconds() - cpu
    return {"windows": n, "seconds": seconds, "cpu_s": cpu, "windows_per_s": n / seconds, **_peak_rss()}


def step_build_windows(corpus: Path, cache: Path) -> dict:
    from beatlite.data.index import index_folder
    from beatlite.data.windows import build_windows

    tic = time.perf_counter()
    w = build_windows(index_folder(corpus), split="train", cache=cache)
    seconds = time.perf_counter() - tic
    disk = sum(p.stat().st_size for p in cache.rglob("*") if p.is_file())
    return {"seconds": seconds, "windows": len(w), "disk_gb": disk / 1e9, **_peak_rss()}


def step_stats(corpus: Path, subset: bool) -> dict:
    """Emotion separability streamed over the takes (``iter_corpus``), loading timed apart from scoring.

    ``subset=False`` also scores every window (the O(N^2) alternative) after the 2000-window subset.
    """
    from beatlite.data.index import index_folder
    from beatlite.stats import emotion_features, iter_corpus
    from beatlite.stats.emotion_clusters import MAX_WINDOWS, separability

    tic = time.perf_counter()
    features = emotion_features(iter_corpus(index_folder(corpus)))
    load_s, rss_load = time.perf_counter() - tic, _peak_rss()["rss_main_gib"]
    out = {"load_s": load_s, "rss_load_gib": rss_load, "n_windows": len(features)}
    for name, max_windows in [("subset", MAX_WINDOWS)] + ([] if subset else [("all", None)]):
        tic = time.perf_counter()
        ef = features.subsample(max_windows, 0)
        if len(np.unique(ef.emotion)) < 2:  # e.g. only neutral takes: separability is undefined
            out.update({f"{name}_s": float("nan"), f"{name}_n": 0, "note": "fewer than 2 emotions"})
            continue
        sep = separability(ef.features, ef.emotion, groups=ef.take, seed=0)
        out.update(
            {
                f"{name}_s": time.perf_counter() - tic,
                f"{name}_n": sep.n,
                f"rss_{name}_gib": _peak_rss()["rss_main_gib"],
            }
        )
        out[f"{name}_balanced_accuracy"] = sep.balanced_accuracy
    out.update(seconds=load_s + out["subset_s"], n=out["subset_n"], **_peak_rss())
    return out


def run_step(args: list[str], script: str = __file__) -> dict:
    """Run ``script`` (this file, or another bench script) with ``args`` (``--step ...``) in a fresh interpreter,
    so that the step's peak RSS is its own; returns the JSON of its last line (``RuntimeError`` with its stderr's
    end when it fails)."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")])}
    out = subprocess.run(
        [sys.executable, script, *args], capture_output=True, text=True, env=env, check=False
    )
    if out.returncode != 0:
        raise RuntimeError(f"step {args[:2]} failed:\n{out.stderr[-3000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


# ---------------------------------------------------------------------- report
def growth_exponent(hours: list[float], values: list[float]) -> float:
    """Least-squares slope of log(values) on log(hours) (nan with fewer than 2 sizes)."""
    if len(hours) < 2:
        return float("nan")
    return float(np.polyfit(np.log(hours), np.log(np.maximum(values, 1e-12)), 1)[0])


def print_table(rows: list[dict]) -> None:
    cols = [
        ("hours", "mocap h", "{:.2f}"),
        ("make_s", "make corpus s", "{:.0f}"),
        ("source_gb", "source GB", "{:.2f}"),
        ("index_s", "index_folder s", "{:.1f}"),
        ("store_s", "store build s", "{:.1f}"),
        ("store_s_per_h", "build s/h", "{:.1f}"),
        ("store_cpu_per_h", "build CPU s/h", "{:.1f}"),
        ("noop_s", "no-op rebuild s", "{:.2f}"),
        ("store_rss_main", "build RSS main GiB", "{:.2f}"),
        ("store_rss_child", "build RSS worker GiB", "{:.2f}"),
        ("store_gb", "store GB", "{:.3f}"),
        ("store_gb_per_h", "store GB/h", "{:.3f}"),
        ("train_windows", "train windows", "{:d}"),
        ("epoch_wps", "loader windows/s", "{:.0f}"),
        ("epoch_rss_main", "epoch RSS main GiB", "{:.2f}"),
        ("epoch_rss_child", "epoch RSS worker GiB", "{:.2f}"),
        ("epoch_cpu_ms", "epoch CPU ms/window", "{:.2f}"),
        ("epoch0_wps", "loader 0 workers windows/s", "{:.0f}"),
        ("epoch0_rss", "epoch 0 workers RSS GiB", "{:.2f}"),
        ("sep_s", "separability (streamed) s", "{:.1f}"),
        ("sep_rss", "separability RSS GiB", "{:.2f}"),
        ("sep_n", "separability windows", "{:d}"),
        ("bw_s", "build_windows s", "{:.1f}"),
        ("bw_rss", "build_windows RSS GiB", "{:.2f}"),
        ("bw_gb", "build_windows store GB", "{:.3f}"),
    ]
    print("| " + " | ".join(c[1] for c in cols) + " |")
    print("|" + "---|" * len(cols))
    for r in rows:
        print("| " + " | ".join(fmt.format(r[k]) if k in r else "-" for k, _, fmt in cols) + " |")
    hours = [r["hours"] for r in rows]
    exps = []
    for key, label, _ in cols[3:]:
        vals = [r.get(key) for r in rows]
        if all(v is not None for v in vals) and key not in ("hours",):
            exps.append(f"{label} {growth_exponent(hours, vals):.2f}")
    print("\ngrowth exponents (log-log slope vs mocap hours): " + "; ".join(exps))


def run_size(hours: float, args: argparse.Namespace, tmp: Path) -> dict:
    corpus, store, cache = tmp / "corpus", tmp / "store", tmp / "windows_cache"
    tic = time.perf_counter()
    n_takes = make_corpus(args.data, corpus, hours, args.workers)
    row: dict = {"takes": n_takes, "make_s": time.perf_counter() - tic}
    row["source_gb"] = sum(p.stat().st_size for p in corpus.rglob("*") if p.is_file()) / 1e9
    s = run_step(["--step", "store", str(corpus), str(store), str(args.workers)])
    h = s["mocap_hours"]
    row["index_s"] = s["index_s"]
    row.update(hours=h, store_s=s["seconds"], noop_s=s["noop_rebuild_s"], store_gb=s["disk_gb"])
    row.update(store_rss_main=s["rss_main_gib"], store_rss_child=s["rss_child_gib"])
    row.update(
        train_windows=s["train_windows"], store_s_per_h=s["seconds"] / h, store_cpu_per_h=s["cpu_s"] / h
    )
    row["store_gb_per_h"] = s["disk_gb"] / h
    e = run_step(["--step", "epoch", str(store), str(args.loader_workers), ",".join(CAMN_KEYS)])
    row.update(
        epoch_wps=e["windows_per_s"], epoch_rss_main=e["rss_main_gib"], epoch_rss_child=e["rss_child_gib"]
    )
    row["epoch_cpu_ms"] = 1000 * e["cpu_s"] / e["windows"]
    e0 = run_step(["--step", "epoch", str(store), "0", ",".join(CAMN_KEYS)])
    row.update(epoch0_wps=e0["windows_per_s"], epoch0_rss=e0["rss_main_gib"])
    if args.stats:
        st = run_step(["--step", "stats", str(corpus), "subset"])
        row.update(sep_s=st["seconds"], sep_rss=st["rss_main_gib"], sep_n=st["n"])
    if hours <= args.compare_max_hours:
        b = run_step(["--step", "build_windows", str(corpus), str(cache)])
        row.update(bw_s=b["seconds"], bw_rss=b["rss_main_gib"], bw_gb=b["disk_gb"])
    print(
        f"  {hours:g} h: {json.dumps({k: round(v, 3) if isinstance(v, float) else v for k, v in row.items()})}"
    )
    return row


def main() -> int:
    if len(sys.argv) > 1 and sys.argv[1] == "--step":
        step = sys.argv[2]
        if step == "store":
            out = step_store(Path(sys.argv[3]), Path(sys.argv[4]), int(sys.argv[5]))
        elif step == "stats":
            out = step_stats(Path(sys.argv[3]), sys.argv[4] == "subset")
        elif step == "epoch":
            out = step_epoch(Path(sys.argv[3]), int(sys.argv[4]), tuple(sys.argv[5].split(",")))
        else:
            out = step_build_windows(Path(sys.argv[3]), Path(sys.argv[4]))
        print(json.dumps(out))
        return 0
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument(
        "--hours", type=float, nargs="+", default=[0.25, 1.0], help="corpus sizes (default 0.25 1)"
    )
    p.add_argument("--data", type=Path, default=REPO / "data_samples", help="source BEAT-format folder")
    p.add_argument("--workers", type=int, default=2, help="store build (and corpus making) processes")
    p.add_argument("--loader-workers", type=int, default=2, help="DataLoader workers of the epoch")
    p.add_argument("--compare-max-hours", type=float, default=1.0, help="run build_windows up to this size")
    p.add_argument("--stats", action="store_true", help="also time emotion_separability over iter_corpus")
    p.add_argument("--keep", type=Path, default=None, help="keep corpora and stores under this folder")
    p.add_argument(
        "--json", type=Path, default=None, help="write the rows, command, revision and machine here"
    )
    args = p.parse_args()
    about = record_about(threads=n_threads())  # (the steps' torch threads)
    print(f"bench_scale: {os.cpu_count()} CPUs; sizes {args.hours} h")
    if args.keep is not None:
        args.keep.mkdir(parents=True, exist_ok=True)
    rows = []
    for hours in sorted(args.hours):
        base = Path(tempfile.mkdtemp(prefix=f"bench_scale_{hours:g}h_", dir=args.keep))
        try:
            rows.append(run_size(hours, args, base))
            if args.json is not None:  # after every size: a run stopped later keeps the sizes it measured
                write_json(args.json, {**about, "rows": rows})
        finally:
            if args.keep is None:
                shutil.rmtree(base, ignore_errors=True)
    print()
    print_table(rows)
    print(
        f"\ntargets: RSS <= 2 GiB; store <= 0.5 GB/h; build <= 30 s/h (2 cores); "
        f"loader >= {5 * CAMN_TINY_WINDOWS_PER_S:.0f} windows/s (5 x CaMN tiny's {CAMN_TINY_WINDOWS_PER_S:.0f})"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
