"""What librosa's numba compilation costs once per fresh environment (the notebooks' "~20 s once").

Times :func:`beatlite.metrics.beats.warm_up` (every librosa numba function that beat detection runs) in a new
Python process with an empty ``NUMBA_CACHE_DIR`` (compiled and cached), then in new processes reading that cache,
and records both beside the process's import time (``import beatlite.metrics.beats``, librosa included).

Run:  ``.venv/bin/python bench/bench_numba.py [--repeat 3] [--json bench/records/numba_cpu.json]``. Timings on a
shared machine are noisy: run it when the machine is idle.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from beatlite.io.atomic import write_json
from beatlite.paths import record_about

CODE = (
    "import time; t = time.perf_counter(); from beatlite.metrics.beats import warm_up; i = time.perf_counter(); "
    "warm_up(); print(i - t, time.perf_counter() - i)"
)


def run_once(cache: Path) -> tuple[float, float]:
    """(import seconds, ``warm_up`` seconds) in a fresh interpreter whose numba cache is ``cache``."""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    out = subprocess.run([sys.executable, "-c", CODE], capture_output=True, text=True, env=env)
    if out.returncode != 0:
        raise SystemExit(f"warm_up failed:\n{out.stderr}")
    imported, warm = (float(x) for x in out.stdout.split()[-2:])
    return imported, warm


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=3, help="cold runs (each with a new empty cache)")
    parser.add_argument("--json", type=Path, help="write the record here")
    args = parser.parse_args()
    about = record_about()
    cold, warm = [], []
    for _ in range(args.repeat):
        with tempfile.TemporaryDirectory(prefix="bench_numba_") as cache:
            cold.append(run_once(Path(cache)))
            warm.append(run_once(Path(cache)))
    for name, runs in (("empty cache", cold), ("cached", warm)):
        print(f"{name:12s} import {min(r[0] for r in runs):5.2f} s, warm_up {min(r[1] for r in runs):6.2f} s")
    if args.json:
        write_json(args.json, {**about,
                               "cold": [{"import_seconds": i, "warm_up_seconds": w} for i, w in cold],
                               "cached": [{"import_seconds": i, "warm_up_seconds": w} for i, w in warm]})  # fmt: skip


if __name__ == "__main__":
    main()
