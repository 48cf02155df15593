"""Retrain HA2G's shipped checkpoints (tiny preset, full model + ablations) with the shared harness.

``python -m beatlite.train retrain-all`` calls :func:`retrain` (also usable on its own:
``python -m beatlite.models.ha2g_train [--only ha2g_tiny ...] [--epochs N]``). Each checkpoint in
:data:`beatlite.models.ha2g.CHECKPOINTS` is trained by :func:`beatlite.train.fit` on the train
windows of ``$BEATLITE_DATA`` (default ``data_samples/``), validated on the val windows,
saved in full to ``build/train/<name>.pt`` and exported (float16, no optimiser) to
``checkpoints/<name>.pt``.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Sequence

DEFAULT_EPOCHS = 20
"""Epochs of each shipped tiny checkpoint (sized for about 3 minutes on one CPU thread)."""
DEFAULT_LR = 1e-3
"""Adam learning rate of the tiny checkpoints (the reference uses 5e-4 at batch 96 for 100 epochs)."""


def retrain(
    names: Sequence[str] | None = None,
    *,
    epochs: int = DEFAULT_EPOCHS,
    batch_size: int = 32,
    lr: float = DEFAULT_LR,
    seed: int = 2021,
    resume: bool = False,
    progress: bool = True,
) -> dict[str, float]:
    """Train and export HA2G checkpoints.

    Parameters
    ----------
    names : sequence of str, optional
        Keys of :data:`beatlite.models.ha2g.CHECKPOINTS` (default: all).
    epochs, batch_size, seed : int
        Harness settings (:class:`beatlite.train.TrainConfig`).
    lr : float
        Generator learning rate (the discriminator's is ``TrainConfig.d_lr_weight`` = 0.2 times it).
    resume : bool
        Continue each ``build/train/<name>.pt`` training checkpoint up to ``epochs`` (the losses
        equal those of an uninterrupted run).
    progress : bool
        Show the tqdm bar.

    Returns
    -------
    dict name -> seconds of training
    """
    import torch

    from beatlite.data.index import index_folder
    from beatlite.data.vocab import build_vocab, take_sentences, word_vectors
    from beatlite.data.windows import build_windows
    from beatlite.models.ha2g import CHECKPOINTS, build_ha2g
    from beatlite.paths import build_dir, checkpoints_dir, data_dir
    from beatlite.train import TrainConfig, export_checkpoint, fit

    chosen = list(CHECKPOINTS) if names is None else list(names)
    unknown = sorted(set(chosen) - set(CHECKPOINTS))
    if unknown:
        raise ValueError(f"unknown HA2G checkpoint(s) {unknown}; known: {sorted(CHECKPOINTS)}")
    index = index_folder(data_dir())
    vocab = build_vocab(index)
    train = build_windows(index, split="train", vocab=vocab)
    val = build_windows(index, split="val", vocab=vocab, stats=(train.pose_norm, train.dir_norm))
    meta = {
        "pose_mean": train.pose_norm.mean,
        "pose_std": train.pose_norm.std,
        "dirvec_mean": train.dir_norm.mean,
        "vocab": list(vocab.itos),
        "data": str(data_dir()),
    }
    seconds = {}
    for name in chosen:
        torch.manual_seed(seed)
        model = build_ha2g("tiny", vocab_size=len(vocab), **CHECKPOINTS[name])
        model.set_word_vectors(
            word_vectors(vocab, take_sentences(index), dim=model.config.word_dim, seed=seed)
        )
        full = build_dir() / "train" / f"{name}.pt"
        config = TrainConfig(
            epochs=epochs,
            batch_size=batch_size,
            lr=lr,
            seed=seed,
            checkpoint=full,
            resume=resume,
            progress=progress,
        )
        start = time.perf_counter()
        fit(model, train, config, val, meta=meta)  # prepare() recovers the direction mean
        seconds[name] = time.perf_counter() - start
        export_checkpoint(full, checkpoints_dir() / f"{name}.pt")
        print(f"{name}: {seconds[name]:.0f} s, {model.n_parameters()} parameters", flush=True)
    return seconds


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m beatlite.models.ha2g_train", description=__doc__.splitlines()[0]
    )
    parser.add_argument("--only", nargs="*", help="checkpoint names (default: all)")
    parser.add_argument("--epochs", type=int, default=DEFAULT_EPOCHS)
    parser.add_argument("--batch-size", type=int, default=32)
    parser.add_argument("--lr", type=float, default=DEFAULT_LR)
    parser.add_argument("--seed", type=int, default=2021)
    parser.add_argument("--resume", action="store_true", help="continue build/train/<name>.pt")
    args = parser.parse_args(argv)
    retrain(
        args.only or None,
        epochs=args.epochs,
        batch_size=args.batch_size,
        lr=args.lr,
        seed=args.seed,
        resume=args.resume,
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
