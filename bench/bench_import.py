"""Benchmark: ``import beatlite, beatlite.io, beatlite.skeleton`` in a fresh interpreter (target <= 0.5 s).

Run:  .venv/bin/python bench/bench_import.py [--repeat 5]

Each repeat starts a new Python process and times the import inside it; the best of N is
reported beside the same measurement of ``import numpy`` alone (the floor: beatlite's I/O and
skeleton layers need numpy and nothing heavier; ``tests/test_project.py::test_import_is_lazy``
asserts that torch, scipy, librosa, matplotlib, ... stay unloaded). Timings on a shared machine
are noisy: run it when the machine is idle.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
TARGET_S = 0.5


def import_seconds(statement: str, repeat: int) -> float:
    """Best of ``repeat`` wall times of ``statement`` in a fresh interpreter, seconds."""
    code = f"import time; t = time.perf_counter(); {statement}; print(time.perf_counter() - t)"
    times = []
    for _ in range(repeat):
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=REPO)
        if out.returncode != 0:
            raise SystemExit(f"{statement!r} failed:\n{out.stderr}")
        times.append(float(out.stdout.strip().splitlines()[-1]))
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    numpy_s = import_seconds("import numpy", args.repeat)
    beatlite_s = import_seconds("import beatlite, beatlite.io, beatlite.skeleton", args.repeat)
    print(f"import numpy                               {numpy_s:6.3f} s")
    print(
        f"import beatlite, beatlite.io, .skeleton    {beatlite_s:6.3f} s  ({beatlite_s / numpy_s:.1f}x numpy)"
    )
    print(f"target <= {TARGET_S} s: {'met' if beatlite_s <= TARGET_S else 'NOT met'}")


if __name__ == "__main__":
    main()
