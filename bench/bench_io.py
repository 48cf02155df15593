"""Benchmark: reading a BEAT-size BVH take (targets on 2 cores: read <= 120 ms, read + FK <= 200 ms).

Run:  BEATLITE_THREADS=1 .venv/bin/python bench/bench_io.py [--repeat 5] [--frames 7200]

Generates a take of BEAT's size (75 joints, 228 channels, 7200 frames at 120 fps = one
minute, ~16 MB, smooth random-walk angles printed with 6 decimals) in a temporary folder,
then prints the best-of-N time of

- ``read_bvh`` (beatlite: one ``np.loadtxt`` call on the raw MOTION bytes, which also checks
  that every row has 228 values),
- ``read_bvh`` + ``forward_kinematics`` (``beatlite.skeleton.kinematics``),
- a straightforward pure-Python reader (``[float(x) for x in line.split()]`` per line),
- other vectorised parsers of the same MOTION bytes (``np.fromstring``, ``np.array(text.split())``)
  to show the numpy floor,

with ratios against the pure-Python reader. Timings on a shared machine are noisy: the best
of several repeats is reported; run it when the machine is idle.
"""

from __future__ import annotations

import argparse
import io
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from beatlite.io import Motion, read_bvh, write_bvh


def beat_size_motion(n_frames: int, seed: int = 0) -> Motion:
    """A (n_frames, 228) motion on the BEAT skeleton: random-walk degrees, hips translation in cm."""
    from beatlite.skeleton.beat import beat_skeleton

    skeleton = beat_skeleton()
    rng = np.random.default_rng(seed)
    channels = np.cumsum(rng.normal(0, 0.5, (n_frames, skeleton.n_channels)), axis=0)
    channels[:, :3] = np.cumsum(rng.normal(0, 0.05, (n_frames, 3)), axis=0) + [0, 95, 0]
    return Motion(skeleton, np.round(channels, 6), fps=120)


def naive_read(path: Path) -> np.ndarray:
    """The obvious pure-Python reader: skip to 'Frame Time', then float() every token, line by line."""
    rows = []
    with open(path) as f:
        for line in f:
            if line.startswith("Frame Time"):
                break
        for line in f:
            if line.strip():
                rows.append([float(x) for x in line.split()])
    return np.array(rows)


def motion_bytes(path: Path) -> bytes:
    data = path.read_bytes()
    start = data.index(b"\n", data.index(b"Frame Time")) + 1
    return data[start:]


def best_of(fn: Callable[[], object], repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--frames", type=int, default=7200)
    args = parser.parse_args()

    from beatlite.skeleton.kinematics import forward_kinematics

    motion = beat_size_motion(args.frames)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "bench_take.bvh"
        t0 = time.perf_counter()
        write_bvh(path, motion)
        t_write = time.perf_counter() - t0
        size_mb = path.stat().st_size / 1e6
        print(
            f"take: {args.frames} frames x {motion.skeleton.n_channels} channels, {size_mb:.1f} MB "
            f"(write_bvh {t_write * 1e3:.0f} ms)"
        )

        back = read_bvh(path)
        assert np.array_equal(back.channels, motion.channels), "round trip failed"
        assert np.array_equal(naive_read(path), motion.channels), "naive reader disagrees"
        data = motion_bytes(path)
        text = data.decode()

        results = {
            "read_bvh": best_of(lambda: read_bvh(path), args.repeat),
            "read_bvh + forward_kinematics": best_of(
                lambda: forward_kinematics((m := read_bvh(path)).skeleton, m.channels), args.repeat
            ),
            "forward_kinematics only": best_of(
                lambda: forward_kinematics(back.skeleton, back.channels), args.repeat
            ),
            "parse only: np.loadtxt(BytesIO) (used)": best_of(
                lambda: np.loadtxt(io.BytesIO(data), ndmin=2, comments=None), args.repeat
            ),
            "parse only: np.fromstring(sep=' ')": best_of(lambda: np.fromstring(text, sep=" "), args.repeat),
            "parse only: np.array(text.split(), float)": best_of(
                lambda: np.array(text.split(), dtype=np.float64), args.repeat
            ),
            "pure-Python per-line reader": best_of(lambda: naive_read(path), max(1, args.repeat // 2)),
        }
    naive = results["pure-Python per-line reader"]
    print(f"best of {args.repeat} runs (noisy on a shared machine):")
    for name, seconds in results.items():
        print(f"  {name:<45s} {seconds * 1e3:8.1f} ms   {naive / seconds:5.1f}x faster than pure Python")
    print("targets (2 cores): read_bvh <= 120 ms, read_bvh + forward_kinematics <= 200 ms")


if __name__ == "__main__":
    main()
