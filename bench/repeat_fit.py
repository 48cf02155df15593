"""Do two trainings with the same seed give the same weights, to the bit? (the determinism a GPU keeps)

Trains a recipe twice on ``data_samples/`` with the same seed, device and ``TrainConfig.deterministic``
(:func:`beatlite.train.recipes.retrain`) and compares the two full training checkpoints: every parameter and
buffer bit for bit (and the largest difference where they differ), and the per-epoch losses. On the CPU the
project's claim is "the same numbers for a seed and thread count"; on CUDA with ``deterministic`` on, torch's
deterministic algorithms are asked for; with it off (``fit --nondeterministic``) some kernels may add in
another order each run.

Usage: ``python bench/repeat_fit.py [--recipes camn_tiny ha2g_tiny] [--device cuda] [--epochs 2]
[--deterministic on off] [--json FILE]`` (a CPU run of the defaults takes about a minute per recipe).
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

import torch

from beatlite.train.checkpoint import load_checkpoint
from beatlite.train.recipes import RECIPES, retrain, training_data


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


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--recipes", nargs="+", default=["camn_tiny", "ha2g_tiny"], choices=sorted(RECIPES))
    p.add_argument("--device", default="cuda" if torch.cuda.is_available() else "cpu")
    p.add_argument("--epochs", type=int, default=2)
    p.add_argument("--seed", type=int, default=2022)
    p.add_argument("--deterministic", nargs="+", default=["on", "off"], choices=["on", "off"])
    p.add_argument("--json", type=Path, default=None)
    args = p.parse_args()
    data, rows = training_data(), []
    for name in args.recipes:
        for det in args.deterministic:
            with tempfile.TemporaryDirectory() as tmp:
                runs, start = [], time.perf_counter()
                for k in range(2):
                    out = Path(tmp) / str(k)
                    retrain(name, seed=args.seed, epochs=args.epochs, out_dir=out, data=data, progress=False,
                            device=args.device, deterministic=det == "on")  # fmt: skip
                    runs.append(load_checkpoint(out / "train" / f"{name}.pt"))
                row = {"recipe": name, "device": args.device, "deterministic": det == "on", "epochs": args.epochs,
                       "seconds": time.perf_counter() - start, **compare(*runs)}  # fmt: skip
            rows.append(row)
            print(json.dumps(row), flush=True)
            if args.json is not None:
                args.json.parent.mkdir(parents=True, exist_ok=True)
                args.json.write_text(
                    json.dumps(
                        {
                            "command": " ".join(["python", *sys.argv]),
                            "torch": torch.__version__,
                            "threads": torch.get_num_threads(),
                            "rows": rows,
                        },
                        indent=1,
                    )
                    + "\n"
                )


if __name__ == "__main__":
    main()
