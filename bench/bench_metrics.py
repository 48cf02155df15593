"""Benchmark of beatlite.metrics against straightforward implementations of the same formulas.

Run: ``BEATLITE_THREADS=1 .venv/bin/python bench/bench_metrics.py [--repeat 5]``

Targets (2 shared cores): BeatAlign of a 10-minute take, audio onsets included, <= 0.6 s;
FGD of 4000 x 300 features <= 60 ms. Timings on a shared machine are noisy: the best of
``--repeat`` runs is printed, with the ratio to the straightforward version measured in the
same run.

BLAS threads follow ``OPENBLAS_NUM_THREADS`` / ``OMP_NUM_THREADS`` if set, else ``BEATLITE_THREADS``
(default 1): on a busy shared machine two spin-waiting OpenBLAS threads make the FGD matrix
products ~5x slower than one thread; on an idle 2-core machine try ``BEATLITE_THREADS=2``.
"""

from __future__ import annotations

import argparse
import os
import time

if "OPENBLAS_NUM_THREADS" not in os.environ and "OMP_NUM_THREADS" not in os.environ:
    os.environ["OPENBLAS_NUM_THREADS"] = os.environ.get("BEATLITE_THREADS", "1")  # before numpy loads BLAS

import numpy as np  # noqa: E402


def best_times(fn, repeat: int) -> tuple[float, float, object]:
    """(best wall time s, best CPU time s of this process, last result) over ``repeat`` runs."""
    wall = cpu = float("inf")
    out = None
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        wall = min(wall, time.perf_counter() - t0)
        cpu = min(cpu, time.process_time() - c0)
    return wall, cpu, out


def synth_take(minutes: float = 10.0, sr: int = 16000, fps: float = 15.0, joints: int = 47, seed: int = 0):
    """Clicks (every ~0.5 s, jittered) + noise, and positions whose speed dips near the clicks."""
    rng = np.random.default_rng(seed)
    dur = minutes * 60
    clicks = np.cumsum(rng.uniform(0.35, 0.7, int(dur / 0.35)))
    clicks = clicks[clicks < dur - 1]
    y = (0.01 * rng.normal(size=int(dur * sr))).astype(np.float32)
    n = int(0.01 * sr)
    click = np.hanning(2 * n)[n:] * np.sin(2 * np.pi * 1000 * np.arange(n) / sr) * 0.8
    for c in clicks:
        i = int(c * sr)
        y[i : i + n] += click.astype(np.float32)
    t = np.arange(int(dur * fps)) / fps
    phase = np.interp(t, np.concatenate([[0], clicks, [dur]]), np.arange(len(clicks) + 2) * np.pi)
    amp = rng.uniform(2, 15, joints)
    pos = np.zeros((len(t), joints, 3))
    pos[:, :, 0] = np.cos(phase)[:, None] * amp
    pos[:, :, 1] = np.sin(0.3 * t)[:, None] * amp * 0.1
    pos += 0.01 * rng.normal(size=pos.shape)
    return y, pos, sr, fps


def loop_beat_align(y, pos, sr, fps, sigma=0.3, order=2):
    """Straightforward version: librosa onset_detect on the waveform, Python loops for minima and nearest beats."""
    import librosa

    onsets = librosa.onset.onset_detect(y=y, sr=sr, units="time")
    scores = []
    for j in range(pos.shape[1]):
        p = pos[:, j]
        speed = [np.linalg.norm(p[min(t + 1, len(p) - 1)] - p[max(t - 1, 0)]) for t in range(len(p))]
        beats = []
        for t in range(order, len(speed) - order):
            if all(speed[t] < speed[t + k] and speed[t] < speed[t - k] for k in range(1, order + 1)):
                beats.append(t / fps)
        if not beats:
            continue
        s = 0.0
        for a in onsets:
            d = min(abs(a - b) for b in beats)
            s += np.exp(-(d**2) / (2 * sigma**2))
        scores.append(s / len(onsets))
    return float(np.mean(scores))


def naive_fgd(a, b):
    """pytorch-fid: np.cov + scipy.linalg.sqrtm(sigma1 @ sigma2)."""
    from scipy import linalg

    mu1, mu2 = a.mean(0), b.mean(0)
    s1, s2 = np.cov(a, rowvar=False), np.cov(b, rowvar=False)
    covmean = linalg.sqrtm(s1 @ s2).real
    return float(((mu1 - mu2) ** 2).sum() + np.trace(s1) + np.trace(s2) - 2 * np.trace(covmean))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--minutes", type=float, default=10.0)
    parser.add_argument("--skip-loop", action="store_true", help="skip the slow loop BeatAlign")
    args = parser.parse_args()

    from beatlite.metrics import audio_beats, beat_align, fgd

    print(f"BLAS threads: {os.environ.get('OPENBLAS_NUM_THREADS') or os.environ.get('OMP_NUM_THREADS')}; "
          f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs")  # fmt: skip
    y, pos, sr, fps = synth_take(args.minutes)
    print(
        f"BeatAlign: {args.minutes:g} min take, audio {y.shape} @ {sr} Hz, positions {pos.shape} @ {fps:g} fps"
    )
    beat_align(y[: sr * 5], sr, pos[: int(5 * fps)], fps)  # warm-up (librosa caches the mel basis)
    t_fast, c_fast, v_fast = best_times(lambda: beat_align(y, sr, pos, fps), args.repeat)
    t_onset, _, _ = best_times(lambda: audio_beats(y, sr), args.repeat)
    print(
        f"  beatlite beat_align     {t_fast:8.3f} s  (CPU {c_fast:.3f} s; value {v_fast:.4f}; onsets alone {t_onset:.3f} s)  target <= 0.6 s"
    )
    if not args.skip_loop:
        t_loop, _, v_loop = best_times(lambda: loop_beat_align(y, pos, sr, fps), 1)
        print(
            f"  loop implementation     {t_loop:8.3f} s  (value {v_loop:.4f}; librosa default peak picking)"
        )
        print(f"  speed-up                {t_loop / t_fast:8.1f} x")

    rng = np.random.default_rng(1)
    a = rng.normal(size=(4000, 300))
    b = rng.normal(size=(4000, 300)) @ (np.eye(300) + 0.05 * rng.normal(size=(300, 300))) + 0.1
    print("FGD: 4000 x 300 features, two sets")
    t_stable, c_stable, v_stable = best_times(lambda: fgd(a, b), args.repeat)
    t_naive, _, v_naive = best_times(lambda: naive_fgd(a, b), max(1, args.repeat // 2))
    print(
        f"  beatlite fgd (cholesky)    {t_stable * 1e3:8.1f} ms (CPU {c_stable * 1e3:.1f} ms; value {v_stable:.6f})  target <= 60 ms"
    )
    print(f"  np.cov + scipy sqrtm    {t_naive * 1e3:8.1f} ms (value {v_naive:.6f})")
    print(
        f"  speed-up                {t_naive / t_stable:8.1f} x; |difference| {abs(v_stable - v_naive):.2e}"
    )


if __name__ == "__main__":
    main()
