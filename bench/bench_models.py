"""Speed of the tiny models: one training epoch and generating a 60 s take.

Run: ``BEATLITE_THREADS=1 .venv/bin/python bench/bench_models.py [--windows N] [--epochs E]``.

Prints, per model, seconds per training epoch on N windows (fake data with the real
shapes unless ``data_samples/`` windows can be built) and the extrapolated time for E
epochs (target: <= 180 s), and the time to generate a 60 s take with the harness
(34-frame units, stride 30; target <= 2 s) next to one single forward pass over the
whole take (the straightforward alternative, no seeding between units).
Timings on a shared machine are noisy: repeat when idle.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import torch

from beatlite.models import build_model
from beatlite.models.testing import fake_windows
from beatlite.paths import n_threads
from beatlite.train import TrainConfig, fit
from beatlite.train.generation import generate_sequence

MODELS = (("camn", {}), ("s2g", {}), ("trimodal", {}))


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--windows", type=int, default=512)
    parser.add_argument("--epochs", type=int, default=30)
    parser.add_argument("--seconds", type=float, default=60.0)
    args = parser.parse_args()
    torch.set_num_threads(n_threads())
    vocab = 200
    train = fake_windows(args.windows, vocab_size=vocab)
    t = int(args.seconds * 15)
    take = {k: v[0] for k, v in fake_windows(1, n_frames=t, vocab_size=vocab).items()}
    take["speaker"] = 1
    print(f"threads={torch.get_num_threads()} windows={args.windows} take={args.seconds:g}s ({t} frames)")
    for name, kw in MODELS:
        if name != "s2g":
            kw = {**kw, "vocab_size": vocab}
        torch.manual_seed(0)
        model = build_model(name, preset="tiny", no_adv_epochs=0, **kw)
        start = time.perf_counter()
        fit(model, train, TrainConfig(epochs=1, batch_size=32, progress=False))
        epoch_s = time.perf_counter() - start
        model.eval()
        start = time.perf_counter()
        generate_sequence(model, take)
        gen_s = time.perf_counter() - start
        whole = {k: torch.from_numpy(np.asarray(v)[None]) for k, v in take.items() if k != "speaker"}
        whole["speaker"] = torch.tensor([1])
        start = time.perf_counter()
        with torch.no_grad():
            model(whole)
        one_s = time.perf_counter() - start
        print(
            f"{name:9s} params={model.n_parameters():7d}  epoch={epoch_s:6.2f}s  "
            f"x{args.epochs} epochs={epoch_s * args.epochs:7.1f}s (target <= 180)  "
            f"generate {args.seconds:g}s take={gen_s:5.2f}s (target <= 2)  "
            f"single pass={one_s:5.2f}s  ratio={gen_s / one_s:4.1f}x"
        )


if __name__ == "__main__":
    main()
