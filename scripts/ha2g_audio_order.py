"""HA2G's audio learner in beatlite's layer order and in the reference code's, trained and scored side by side.

beatlite's ``HierarchicalAudioEncoder`` runs convolution -> BatchNorm -> ReLU; HA2G's code runs convolution -> ReLU ->
BatchNorm, with a biased stem and ReLU + BatchNorm after each feature stream (``HA2GConfig.audio_order``,
docs/reference_code.md#ha2g-audio). This trains the ``ha2g_tiny`` recipe both ways with the same seeds and scores
them on the data_samples test split, then says, per metric, whether the order makes a difference larger than two
standard errors of the seed means (``beatlite.report.claim``).

Run: ``python scripts/ha2g_audio_order.py --out build/ha2g_audio_order --jobs 2`` (six trainings of about 3-6 min on
one thread each; ``--seeds`` chooses; a checkpoint already in ``--out`` is kept, so a second run only scores).
"""

from __future__ import annotations

import argparse
import dataclasses
import subprocess
import sys
from pathlib import Path

ORDERS = {"beatlite": "HA2G", "reference": "HA2G, reference audio layer order"}
METRICS = ("FGD", "SRGR", "BeatAlign", "BC", "BC (ha2g)", "Diversity")


def _recipe(order: str) -> str:
    """Register the ``ha2g_tiny`` recipe with ``audio_order=order`` (in this process) and return its name."""
    from beatlite.train import recipes

    name = f"ha2g_tiny_audio_{order}"
    base = recipes.RECIPES["ha2g_tiny"]
    recipes.RECIPES[name] = dataclasses.replace(
        base, label=ORDERS[order], overrides={**base.overrides, "audio_order": order}
    )
    return name


def train(order: str, seed: int, out: Path) -> Path:
    """Train one (order, seed) into ``out/<order>/<seed>/``; return the exported checkpoint."""
    from beatlite.train.recipes import retrain

    name = _recipe(order)
    folder = out / order / str(seed)
    if not (folder / f"{name}.pt").is_file():
        seconds = retrain(name, seed=seed, out_dir=folder, progress=False)
        print(f"{order} seed {seed}: {seconds:.0f} s", flush=True)
    return folder / f"{name}.pt"


def score(out: Path, seeds: list[int]) -> str:
    """The seed table and the per-metric verdicts, as Markdown."""
    import beatlite as bl

    test = bl.train.testset.load_test_set()
    values: dict[str, dict[str, list[float]]] = {}
    for order, label in ORDERS.items():
        for seed in seeds:
            model, checkpoint = bl.train.load_model(out / order / str(seed) / f"ha2g_tiny_audio_{order}.pt")
            norms = bl.data.normalize.Normalizers.from_meta(checkpoint["meta"])
            row = bl.train.evaluation.evaluate_models([(label, model, norms)], test=test, columns=METRICS)
            for key in METRICS:
                values.setdefault(label, {}).setdefault(key, []).append(row.get(label).metrics[key])
    record = bl.train.seeds.SeedResults(values, seeds, {})
    table = record.to_markdown(METRICS, list(ORDERS.values()))
    verdicts = [str(bl.report.claim(record, ORDERS["reference"], ORDERS["beatlite"], key)) for key in METRICS]
    return table + "\n\n" + "\n".join(f"- {v}" for v in verdicts)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("build/ha2g_audio_order"))
    parser.add_argument("--seeds", type=int, nargs="+", default=[2021, 2022, 2023])
    parser.add_argument("--jobs", type=int, default=1, help="training processes at once (1 thread each)")
    parser.add_argument("--one", nargs=2, metavar=("ORDER", "SEED"), help=argparse.SUPPRESS)  # a worker's job
    args = parser.parse_args()
    if args.one:
        train(args.one[0], int(args.one[1]), args.out)
        return 0
    jobs = [(order, seed) for order in ORDERS for seed in args.seeds]
    running: list[subprocess.Popen] = []
    failed = 0
    for order, seed in jobs:
        if len(running) >= args.jobs:
            failed += running.pop(0).wait() != 0
        cmd = [sys.executable, __file__, "--out", str(args.out), "--one", order, str(seed)]
        running.append(subprocess.Popen(cmd))
    failed += sum(p.wait() != 0 for p in running)
    if failed:
        print(f"{failed} trainings failed", file=sys.stderr)
        return 1
    print(score(args.out, args.seeds))
    return 0


if __name__ == "__main__":
    sys.exit(main())
