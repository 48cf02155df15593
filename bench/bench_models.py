"""Speed of the tiny models: one training epoch, the full shipped training, generating a 60 s take.

Run: ``BEATLITE_THREADS=1 .venv/bin/python bench/bench_models.py [--windows N] [--seconds S]``.

Per model it prints the seconds of a plain and of an adversarial training epoch (the fastest of
``--repeats``, default 2) on the ``data_samples/`` train windows (fake windows with the real
shapes when the folder is missing; ``--windows`` keeps the first N), the seconds of one validation-FGD scoring (the recipes keep the
best epoch by it), the extrapolated time of the shipped training (its recipe in
``beatlite.train.recipes.RECIPES``: 60 epochs, HA2G 30, the last ``epochs - no_adv_epochs``
adversarial, plus one scoring per epoch; target <= 180 s per model on 2 cores), and the time to
generate a 60 s take with the harness (34-frame units, stride 30; target <= 2 s) next to one
single forward pass over the whole take (the straightforward alternative, no seeding between
units).
Run it with ``BEATLITE_THREADS=2`` for the 2-core figure.
Timings on a shared machine are noisy: repeat when idle.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import torch

from beatlite.models import build_model
from beatlite.models.testing import fake_windows
from beatlite.paths import data_dir, n_threads
from beatlite.train import TrainConfig, fit
from beatlite.train.generation import generate_sequence
from beatlite.train.recipes import RECIPES

MODELS = (
    ("camn_tiny", "camn tiny"),
    ("s2g_tiny", "s2g tiny"),
    ("trimodal_tiny", "trimodal tiny"),
    ("ha2g_tiny", "ha2g tiny"),
)
"""(recipe name, label) of the timed models."""


def _train_windows(limit: int | None) -> tuple[dict[str, np.ndarray], int, str, dict]:
    try:
        from beatlite.data.index import index_folder
        from beatlite.data.vocab import build_vocab
        from beatlite.data.windows import build_windows

        index = index_folder(data_dir())
        vocab = build_vocab(index)
        w = build_windows(index, split="train", vocab=vocab)
        arrays = {k: w[k] for k in w.keys()}
        meta = w.normalizers.to_meta()
        source = f"{data_dir().name} train windows"
        n_vocab = len(vocab)
    except (OSError, ValueError) as exc:
        print(f"(no data: {exc}; using fake windows)")
        n_vocab = 200
        arrays = fake_windows(limit or 658, vocab_size=n_vocab)
        meta = {"pose_mean": np.zeros(141), "pose_std": np.ones(141), "dirvec_mean": np.zeros(126)}
        source = "fake windows"
    if limit is not None:
        arrays = {k: v[:limit] for k, v in arrays.items()}
    return arrays, n_vocab, source, meta


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--windows", type=int, default=None, help="use only the first N train windows")
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument(
        "--repeats", type=int, default=2, help="time each kind of epoch N times, keep the fastest"
    )
    args = parser.parse_args()
    torch.set_num_threads(n_threads())
    train, vocab, source, meta = _train_windows(args.windows)
    n = len(train["pose"])
    t = int(args.seconds * 15)
    take = {k: v[0] for k, v in fake_windows(1, n_frames=t, vocab_size=vocab).items()}
    take["speaker"] = 1
    print(f"threads={torch.get_num_threads()} {source}: {n} windows; take={args.seconds:g}s ({t} frames)")
    try:  # the per-epoch validation FGD of the recipes (select_best)
        from beatlite.train.testset import fgd_scorer

        score = fgd_scorer("val")
    except (OSError, ValueError) as exc:
        print(f"(no validation takes: {exc}; validation FGD not timed)")
        score = None
    for recipe_name, label in MODELS:
        recipe = RECIPES[recipe_name]
        name, epochs = recipe.model, recipe.epochs
        kw = dict(recipe.overrides)
        if recipe.uses_text:
            kw["vocab_size"] = vocab
        per_kind = {}
        for adversarial in (False, True):  # plain and adversarial epochs (with the D step)
            torch.manual_seed(0)
            model = build_model(name, preset="tiny", no_adv_epochs=0 if adversarial else 1, **kw)
            times = []
            for _ in range(args.repeats):  # the fastest of a few: the least disturbed by the machine
                config = TrainConfig(epochs=1, batch_size=recipe.batch_size, lr=recipe.lr, progress=False)
                start = time.perf_counter()
                fit(model, train, config, meta=meta)
                times.append(time.perf_counter() - start)
            per_kind[adversarial] = min(times)
        n_adv = max(0, epochs - int(build_model(name, preset="tiny", **kw).config.no_adv_epochs))
        total_s = per_kind[False] * (epochs - n_adv) + per_kind[True] * n_adv
        epoch_s = per_kind[True]
        model.eval()
        val_s = 0.0
        if score is not None and recipe.select_best:
            start = time.perf_counter()
            with torch.no_grad():
                score(model)
            val_s = time.perf_counter() - start
            total_s += epochs * val_s
        start = time.perf_counter()
        generate_sequence(model, take)
        gen_s = time.perf_counter() - start
        whole = {k: torch.from_numpy(np.asarray(v)[None]) for k, v in take.items() if k != "speaker"}
        whole["speaker"] = torch.tensor([1])
        start = time.perf_counter()
        try:
            with torch.no_grad():
                model(whole)
            one_s = time.perf_counter() - start
        except ValueError:  # HA2G only takes its fixed 34-frame windows
            one_s = float("nan")
        print(
            f"{label:15s} params={model.n_parameters():7d}  epoch={per_kind[False]:5.2f}s (adv {epoch_s:5.2f}s, "
            f"val FGD {val_s:4.2f}s)  {epochs - n_adv}+{n_adv} adv epochs={total_s:6.1f}s (target <= 180)  "
            f"generate {args.seconds:g}s take={gen_s:5.2f}s (target <= 2)  "
            f"single pass={one_s:5.2f}s  ratio={gen_s / one_s:4.1f}x"
        )


if __name__ == "__main__":
    main()
