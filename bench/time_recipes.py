"""How long does a shipped recipe take to train on this CPU? (the README's "Other targets" timings)

Trains each recipe once with its epochs and the seed ``retrain`` defaults to (2021), as ``python -m beatlite.train retrain-all --only NAME
--skip-extractor`` does (one :func:`beatlite.train.recipes.training_data` for all, the window store already built,
best epoch by validation FGD), into a temporary folder, and records the seconds of ``fit`` (the number
``retrain`` returns) and the wall and user-CPU seconds of the whole call (model building and export included).
The torch thread count is ``BEATLITE_THREADS``'s; the record states it, the revision and the machine with its
load average before and after (other jobs slow a timing down: compare rows of one record, measured alone).

Usage: ``BEATLITE_THREADS=2 python bench/time_recipes.py [--recipes camn_tiny ha2g_tiny trimodal_tiny]
[--json bench/records/time_recipes_cpu.json]``.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

import torch

from beatlite.io.atomic import write_json
from beatlite.paths import machine, n_threads, record_about
from beatlite.train.recipes import RECIPES, SEED, retrain, training_data, warm_up


def time_recipe(name: str, data, out: Path) -> dict:
    """One training of ``name``: its epochs, ``fit``'s seconds, and the call's wall and user-CPU seconds."""
    cpu, wall = os.times(), time.perf_counter()
    fit_seconds = retrain(name, seed=SEED, out_dir=out, progress=False, data=data)
    done = os.times()
    return {"recipe": name, "seed": SEED, "epochs": RECIPES[name].epochs,
            "fit_seconds": fit_seconds, "wall_seconds": time.perf_counter() - wall,
            "user_seconds": done.user - cpu.user}  # fmt: skip


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--recipes", nargs="+", default=["camn_tiny", "ha2g_tiny", "trimodal_tiny"],
                        choices=sorted(RECIPES), metavar="RECIPE")  # fmt: skip
    parser.add_argument("--json", type=Path, help="write the record here")
    args = parser.parse_args(argv)
    torch.set_num_threads(n_threads())  # as retrain trains: the threads the record's machine states
    warm_up()  # librosa's numba code compiled before the first timing
    data = training_data(progress=False)  # the window store built (or found) before the first timing
    about = record_about()
    rows = []
    with tempfile.TemporaryDirectory(prefix="time_recipes_") as tmp:
        for name in args.recipes:
            rows.append(time_recipe(name, data, Path(tmp)))
            r = rows[-1]
            print(f"{name}: {r['epochs']} epochs, fit {r['fit_seconds']:.0f} s, wall {r['wall_seconds']:.0f} s, "
                  f"user CPU {r['user_seconds']:.0f} s", flush=True)  # fmt: skip
    after = machine()
    record = {**about, "load_average_after": after["load_average"], "rows": rows}
    if args.json:
        write_json(args.json, record)


if __name__ == "__main__":
    main()
