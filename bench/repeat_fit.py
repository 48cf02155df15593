"""Do two trainings with the same seed give the same weights, to the bit? (the determinism a GPU keeps)

Runs the ``fit`` command twice per recipe and setting, each in its own process (``python -m beatlite.train fit
RECIPE --data data_samples --out DIR --epochs E --device D --seed S [--nondeterministic]``; cuDNN's and cuBLAS's
per-process choices are made afresh each time; the window store is built once, under a shared
``BEATLITE_BUILD``), and compares the two full training checkpoints: every parameter and buffer bit for bit
(and the largest difference where they differ), and the per-epoch losses. On the CPU the project's claim is
"the same numbers for a seed and thread count"; on CUDA with ``deterministic`` on, torch's deterministic
algorithms are asked for; with it off (``--nondeterministic``) some kernels may add in another order each run.

Usage: ``python bench/repeat_fit.py [--recipes camn_tiny ha2g_tiny] [--device cuda] [--epochs 2]
[--deterministic on off] [--json FILE]``; the record gives each pair's seconds.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import torch

from beatlite.io.atomic import write_json
from beatlite.paths import data_dir, n_threads, record_about
from beatlite.train.checkpoint import load_checkpoint
from beatlite.train.recipes import RECIPES


def compare(a: dict, b: dict) -> dict:
    """Bitwise comparison of two training checkpoints' states and histories."""
    differ = {k: float((a["state"][k].double() - b["state"][k].double()).abs().max()) for k in a["state"]
              if not torch.equal(a["state"][k], b["state"][k])}  # fmt: skip
    return {
        "tensors": len(a["state"]),
        "tensors_differing": len(differ),
        "largest_difference": max(differ.values(), default=0.0),
        "histories_equal": a["history"] == b["history"],
    }


def fit_once(name: str, out: Path, build: Path, args: argparse.Namespace, deterministic: bool) -> dict:
    """The full training checkpoint of one ``fit`` command run in a child process."""
    cmd = [sys.executable, "-m", "beatlite.train", "fit", name, "--data", str(data_dir()), "--out", str(out),
           "--epochs", str(args.epochs), "--device", args.device, "--seed", str(args.seed)]  # fmt: skip
    if not deterministic:
        cmd.append("--nondeterministic")
    done = subprocess.run(
        cmd, env={**os.environ, "BEATLITE_BUILD": str(build)}, capture_output=True, text=True
    )
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} exited {done.returncode}:\n{done.stderr[-4000:]}")
    return load_checkpoint(out / "train" / f"{name}.pt")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--recipes", nargs="+", default=["camn_tiny", "ha2g_tiny"], choices=sorted(RECIPES))
    p.add_argument("--device", default="cuda" if torch.cuda.is_available() else "cpu")
    p.add_argument("--epochs", type=int, default=2)
    p.add_argument("--seed", type=int, default=2022)
    p.add_argument("--deterministic", nargs="+", default=["on", "off"], choices=["on", "off"])
    p.add_argument("--json", type=Path, default=None)
    args = p.parse_args()
    torch.set_num_threads(
        n_threads()
    )  # the fits' threads (the fit command's), which the record's machine states
    rows, about = [], record_about()  # (before this run writes its record, a tracked file)
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.recipes:
            for det in args.deterministic:
                start = time.perf_counter()
                runs = [fit_once(name, Path(tmp) / f"{name}-{det}-{k}", Path(tmp) / "build", args, det == "on")
                        for k in range(2)]  # fmt: skip
                rows.append({"recipe": name, "device": args.device, "deterministic": det == "on",
                             "epochs": args.epochs, "seconds": time.perf_counter() - start, **compare(*runs)})  # fmt: skip
                print(json.dumps(rows[-1]), flush=True)
                if args.json is not None:
                    write_json(args.json, {**about, "rows": rows})


if __name__ == "__main__":
    main()
