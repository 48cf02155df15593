"""Benchmark: generating the whole ``data_samples/`` corpus (target: <= 3 min on 2 cores).

Run:  .venv/bin/python bench/bench_synth.py [--workers 2] [--serial]

Generates every take of :func:`beatlite.synth.corpus_specs` into a temporary folder with
``--workers`` processes and prints the wall time, the total duration generated and the real-time
factor. With ``--serial`` it also runs the straightforward alternative in the same run (one process,
takes one after the other) and prints the speed-up. Timings on a shared machine are noisy; run it
twice and compare. Needs espeak-ng.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("BEATLITE_THREADS", "1")

from beatlite.synth import generate_corpus  # noqa: E402


def _run(workers: int) -> tuple[float, float, float]:
    with tempfile.TemporaryDirectory(prefix="bench_synth_") as tmp:
        tic = time.perf_counter()
        results = generate_corpus(tmp, seed=0, workers=workers)
        wall = time.perf_counter() - tic
        size = sum(os.path.getsize(os.path.join(tmp, f)) for f in os.listdir(tmp))
    return wall, sum(r.duration for r in results), size / 2**20


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--serial", action="store_true", help="also time 1 process (the plain loop)")
    args = parser.parse_args()
    wall, seconds, mib = _run(args.workers)
    print(
        f"{args.workers} workers: {wall:6.1f} s wall for {seconds:.1f} s of data ({mib:.1f} MiB), "
        f"{seconds / wall:.1f}x real time; target <= 180 s: {'OK' if wall <= 180 else 'MISSED'}"
    )
    if args.serial:
        wall1, _, _ = _run(1)
        print(f"1 worker : {wall1:6.1f} s wall; speed-up of {args.workers} workers: {wall1 / wall:.2f}x")


if __name__ == "__main__":
    main()
