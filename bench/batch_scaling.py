"""Does a larger batch with scaled learning rates keep a recipe's test scores? (issue 28)

A GPU takes larger batches at about the same time per step, and ``retrain(name, batch_size=B, lr_scaling=R)``
(the ``fit`` command's ``--batch-size B --lr-scaling R``) scales the learning rates with B, linearly or by its
square root (:func:`beatlite.train.recipes.scaled_lr`). This trains the recipe at each batch size with each
rule and seed on ``data_samples/`` (the recipe's epochs, best epoch by validation
FGD, as the shipped checkpoints) and scores every checkpoint on the test split
(:func:`beatlite.train.evaluate_models`, the results table's protocol: FGD on TED-43 directions, SRGR,
BeatAlign, BC, Diversity, L1div), all in one run of the same code.

Usage: ``BEATLITE_THREADS=1 python bench/batch_scaling.py [--recipe camn_tiny] [--batches 32 64 128]
[--rules linear sqrt] [--seeds 2021 2022 2023] [--work DIR] [--json bench/records/batch_scaling_camn_tiny.json]`` (about 2.5 min per
checkpoint on one CPU thread for ``camn_tiny``; ``--work`` keeps the checkpoints, and a checkpoint already
there is scored, not trained again).

Scope: ``data_samples/`` has 658 train windows, so batch 128 is 6 steps per epoch (``--epochs`` gives a run the
steps of another: 140 epochs at 128 take batch 32's 840 steps); whether larger batches keep the scores on real BEAT
(80,000 windows at BEAT-4english) is not measured here.
"""

from __future__ import annotations

import argparse
import json
import statistics
import tempfile
import time
from pathlib import Path
from typing import Any

from beatlite.io.atomic import write_json
from beatlite.paths import n_threads, record_about
from beatlite.train.evaluation import evaluate_models
from beatlite.train.recipes import RECIPES, retrain, scaled_lr, training_data
from beatlite.train.testset import load_test_set

METRICS = ("FGD", "SRGR", "BeatAlign", "BC", "Diversity", "L1div")


def summary(rows: list[dict]) -> dict[str, dict[str, list[float]]]:
    """Per ``"<batch> <rule>"`` and metric: ``[mean, sample sd]`` over the seeds (sd None for one seed)."""
    out: dict[str, dict[str, list[float]]] = {}
    for batch, rule in dict.fromkeys((r["batch"], r["rule"]) for r in rows):
        group = [r for r in rows if (r["batch"], r["rule"]) == (batch, rule)]
        values = {m: [r[m] for r in group] for m in METRICS if all(m in r for r in group)}
        out[f"{batch} {rule}"] = {
            m: [statistics.mean(v), statistics.stdev(v) if len(v) > 1 else None] for m, v in values.items()
        }
    return out


def _record(args: argparse.Namespace, recipe: Any, rows: list[dict]) -> dict:
    batches, rules, seeds = (" ".join(map(str, v)) for v in (args.batches, args.rules, args.seeds))
    return {
        "recipe": args.recipe,
        "recipe_batch": recipe.batch_size,
        "recipe_lr": recipe.lr,
        "epochs": recipe.epochs if args.epochs is None else args.epochs,
        **args.about,
        "command": f"BEATLITE_THREADS={n_threads()} python bench/batch_scaling.py --recipe {args.recipe} "
        f"--batches {batches} --rules {rules} --seeds {seeds}"
        + ("" if args.epochs is None else f" --epochs {args.epochs}"),
        "rows": rows,
        "summary": summary(rows),
    }


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--recipe", default="camn_tiny", choices=sorted(RECIPES))
    p.add_argument("--batches", nargs="+", type=int, default=[32, 64, 128])
    p.add_argument("--rules", nargs="+", default=["linear", "sqrt"], choices=["linear", "sqrt"])
    p.add_argument("--seeds", nargs="+", type=int, default=[2021, 2022, 2023])
    p.add_argument("--epochs", type=int, default=None, help="default the recipe's (1: a smoke test)")
    p.add_argument(
        "--work", type=Path, default=None, help="where the checkpoints go (default a temporary folder)"
    )
    p.add_argument("--json", type=Path, default=None, help="write the record here")
    args = p.parse_args()
    args.about = record_about()  # (before this run writes its record, a tracked file)
    recipe = RECIPES[args.recipe]
    with tempfile.TemporaryDirectory() as tmp:
        work = args.work or Path(tmp)
        data, test = training_data(), load_test_set()
        rows = []
        runs = [(b, "linear" if b == recipe.batch_size else r) for b in args.batches for r in args.rules]
        for batch, rule in dict.fromkeys(runs):  # (the recipe's own batch once: both rules give its lr)
            for seed in args.seeds:
                epochs = recipe.epochs if args.epochs is None else args.epochs
                folder = work / f"{args.recipe}_b{batch}_{rule}_e{epochs}_s{seed}"
                reused, start = (folder / f"{args.recipe}.pt").is_file(), time.perf_counter()
                if not reused:
                    retrain(args.recipe, seed=seed, out_dir=folder, data=data, progress=False, batch_size=batch,
                            lr_scaling=rule, epochs=epochs)  # fmt: skip
                seconds = (
                    None if reused else time.perf_counter() - start
                )  # (a checkpoint of --work: not timed)
                result = evaluate_models([str(folder / f"{args.recipe}.pt")], test=test, ground_truth=False)
                metrics = {k: float(v) for k, v in result.rows[0].metrics.items() if k in METRICS}
                lr = scaled_lr(recipe, batch, rule)
                rows.append({"batch": batch, "rule": rule, "seed": seed, "lr": lr, "train_seconds": seconds,
                             "reused": reused, **metrics})  # fmt: skip
                print(json.dumps(rows[-1]), flush=True)
                if args.json is not None:  # after every row: an interrupted run keeps them
                    write_json(args.json, _record(args, recipe, rows))
    record = _record(args, recipe, rows)
    for key, values in record["summary"].items():
        cells = "  ".join(
            f"{m} {mean:.3g}" + ("" if sd is None else f" ± {sd:.2g}") for m, (mean, sd) in values.items()
        )
        print(f"batch {key}: {cells}")


if __name__ == "__main__":
    main()
